#!/usr/bin/env bash
# Every stage and the drivers end to end on a small CT (a coarse-voxel
# phantom, 1.2 x 1.2 x 1.5 mm, seconds in a release build), so that
# the sanitizer tier runs them all: run on the DICOM series; each stage's
# own executable on the NIfTI; a batch of two subjects, one failing. Each
# result is checked against the phantom's truth. The stages' chain puts the
# edges on the blurred-cortex model (the default here), run and batch on
# the steepest fall (a third of the time).
source "$(dirname "$0")/common.bash"

"$bin/articula" phantom -o "$tmp/p" --seed 8 --model ovoid --spacing 1.2,1.2,1.5 --quiet
ct="$tmp/p/phantom.nii.gz"

# check_head RESULTS: the sphere's centre within 1 mm of the true head's,
# the selected model's RMS under 0.3 mm, the checks passed or warned.
check_head() {
  python3 - "$1" "$tmp/p/truth.json" <<'PY'
import json, math, sys
r, truth = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
sphere = next(m for m in r["models"] if m["model"] == "sphere")
centre = [sphere["parameters"][k] for k in ("t1_mm", "t2_mm", "t3_mm")]
err = math.dist(centre, truth["head_center_mm"])
selected = next(m for m in r["models"] if m["model"] == r["selected_model"])
print(f"{sys.argv[1]}: sphere centre {err:.2f} mm from the truth, selected {r['selected_model']} "
      f"(true {truth['model']}), RMS {selected['errors']['rms_mm']:.3f} mm, qc {r['qc']['status']}")
assert err < 1.0, err
assert selected["errors"]["rms_mm"] < 0.3, selected["errors"]
assert r["qc"]["status"] in ("pass", "warn"), r["qc"]
PY
}

# The driver on the DICOM series.
"$bin/articula" run -i "$tmp/p/dicom" -o "$tmp/run" --quiet --edge-model steepest
check_head "$tmp/run/results.json"
[ -s "$tmp/run/report.html" ] && [ -s "$tmp/run/scene.mrml" ] || fail "run wrote no report or scene"

# Each stage's executable on the NIfTI, chained through files.
s="$tmp/stages"
mkdir -p "$s"
"$bin/articula-segment" -i "$ct" -o "$s/label.nii.gz" --joint hip --side right -q
"$bin/articula-mesh" -i "$s/label.nii.gz" -o "$s/bone.vtp" --ct "$ct" -q
"$bin/articula-sample" -i "$s/bone.vtp" -o "$s/points.ply" -q
"$bin/articula-fit" -i "$s/points.ply" -o "$s/fits.json" -q
"$bin/articula-errors" -i "$s/points.ply" --fits "$s/fits.json" -o "$s/errors" -q
"$bin/articula-report" -i "$s" --ct "$ct" -q
check_head "$s/results.json"

# A batch of two subjects, one whose input is missing: exit 1, the good one
# complete and right, the study tables written.
cat > "$tmp/study.csv" <<CSV
subject,input,joint,side,edge_model
small,p/phantom.nii.gz,hip,right,steepest
missing,p/nowhere.nii.gz,hip,right,steepest
CSV
expect_rc 1 "$bin/articula" batch "$tmp/study.csv" -o "$tmp/study" -j 2 --quiet
check_head "$tmp/study/subjects/small/results.json"
grep -q "^missing,failed,3," "$tmp/study/study_status.csv" || fail "the missing subject: $(cat "$tmp/study/study_status.csv")"
[ "$(grep -c '^small,' "$tmp/study/study.csv")" -eq 5 ] || fail "study.csv: not one row per model"
[ -s "$tmp/study/study.html" ] || fail "no study.html"
echo "small sizes: ok"
