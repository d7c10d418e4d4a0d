#!/usr/bin/env bash
# phantom -> segment -> mesh -> sample end to end, from NIfTI and from DICOM:
# the fitted sphere of the articular points lands on the phantom's true head.
set -euo pipefail
B=$ARTICULA_BIN
T=$ARTICULA_TMP
rm -rf "$T" && mkdir -p "$T"

"$B/articula" phantom -o "$T/p" --seed 5 --model sphere --gap 3 -q
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
