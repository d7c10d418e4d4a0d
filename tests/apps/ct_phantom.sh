#!/usr/bin/env bash
# phantom -> segment -> mesh -> sample end to end, from NIfTI and from DICOM:
# the fitted sphere of the articular points lands on the phantom's true head.
# fixtures: sphere
# labels: full-size
set -euo pipefail
python3() { /usr/bin/python3 "$@"; }  # Debian's, as common.bash binds it
B=$ARTICULA_BIN
T=$ARTICULA_TMP
rm -rf "$T" && mkdir -p "$T"

# The seed-5 sphere phantom (default 3 mm gap), made once for several tests.
ln -s "${ARTICULA_FIXTURES:?}/sphere/phantom" "$T/p"
# NIfTI and DICOM input; and the surface by the level set (active contour).
for run in "$T/p/phantom.nii.gz" "$T/p/dicom" "$T/p/phantom.nii.gz --level-set 100"; do
  read -r input extra <<< "$run"
  "$B/articula-segment" -i "$input" -o "$T/head.nii.gz" --joint hip --side right --force -q $extra
  "$B/articula-mesh" -i "$T/head.nii.gz" -o "$T/head.vtp" --force -q
  "$B/articula-sample" -i "$T/head.vtp" -o "$T/points.ply" --ball-radius 1.0 --seed 1 --force -q --json > "$T/sample.json"
  test -s "$T/points.ply"
  python3 - "$T/p/truth.json" "$T/sample.json" <<'PY'
import json, math, sys
truth, s = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
c, r = truth["head_center_mm"], truth["radii_mm"][0]
fc, fr = s["sphere"]["center_mm"], s["sphere"]["radius_mm"]
err = math.dist(c, fc)
print(f"centre error {err:.3f} mm, radius {fr:.3f} vs {r:.3f} mm, {s['reduced_points']} of {s['selected_points']} points")
assert err < 0.5, err
assert abs(fr - r) < 0.5, (fr, r)
assert 0 < s["reduced_points"] < s["selected_points"]
assert s["provenance"]["coordinate_system"] == "LPS"
PY
done
# Same seed, same points.
"$B/articula-sample" -i "$T/head.vtp" -o "$T/again.ply" --ball-radius 1.0 --seed 1 -q
cmp "$T/points.ply" "$T/again.ply"
# CSV output by --format.
"$B/articula-sample" -i "$T/head.vtp" -o "$T/points.ply" --format csv --seed 1 -q --force
head -1 "$T/points.csv" | grep -q x_mm
# The wider phantom's options reach truth.json: both hips, a fixed radius, a
# spherical socket, a fovea, osteoporotic bone.
"$B/articula" phantom -o "$T/pelvis" --both-hips --side left --radius 18 --socket spherical --fovea --osteoporotic \
  --gap 1.5 --spacing 3,3,3 --no-dicom -q
python3 - "$T/pelvis/truth.json" <<'PY'
import json, math, sys
t = json.load(open(sys.argv[1]))
assert t["both_hips"] and [h["side"] for h in t["hips"]] == ["left", "right"], t["hips"]
assert t["side"] == "left" and t["head_center_mm"] == t["hips"][0]["head_center_mm"]
assert 170 < math.dist(t["hips"][0]["head_center_mm"], t["hips"][1]["head_center_mm"]) < 200
assert t["socket"]["shape"] == "spherical" and "fovea" in t["hips"][1]
assert t["cortical_mm"] == 0.8 and t["hu"]["cancellous"] == 190 and t["joint_gap_mm"] == 1.5
PY
"$B/articula" phantom -o "$T/bad" --radius 60 -q 2>/dev/null && exit 1 || test $? -eq 2
