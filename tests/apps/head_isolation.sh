#!/usr/bin/env bash
# articula run on phantoms that used to fool the head search, each checked
# against the phantom's true head: the left hip whose trochanter was taken
# for the head (seed 1); clinical 1.5 x 1.5 x 3 mm voxels, where the run
# must find the head or refuse, never report another structure. The
# articular points lie on the true surface (mean signed distance of the true
# model's errors). (Narrow gaps and thick slices: head_isolation_pelvis.sh.)
# labels: full-size
source "$(dirname "$0")/common.bash"
source "$(dirname "$0")/head_truth.bash"

# The trochanter case: a left hip (seed 1, ellipsoidal head of radii 19.5-20.5 mm).
"$bin/articula" phantom -o "$tmp/left" --seed 1 --side left --no-dicom -q
"$bin/articula" run -i "$tmp/left/phantom.nii.gz" -o "$tmp/left-run" --side left -q
check "$tmp/left-run" "$tmp/left/truth.json" left 0.5 0.5

# Clinical voxels: the head, or a refusal naming the failed check.
"$bin/articula" phantom -o "$tmp/coarse" --seed 11 --spacing 1.5,1.5,3 --gap 2 --no-dicom -q
set +e
"$bin/articula" run -i "$tmp/coarse/phantom.nii.gz" -o "$tmp/coarse-run" -q 2> "$tmp/coarse.err"
rc=$?
set -e
if [ "$rc" -eq 0 ]; then
  check "$tmp/coarse-run" "$tmp/coarse/truth.json" right 1.5 1.0
else
  [ "$rc" -eq 1 ] || fail "coarse voxels: exit $rc"
  grep -q "qc\|no femoral head" "$tmp/coarse.err" || fail "coarse voxels: refused without a reason: $(cat "$tmp/coarse.err")"
fi
# A damaged output of an up-to-date stage is redone, not kept.
# (Each stage's stamp holds its run time: a stage redone writes a new one.)
cp "$tmp/left-run/results.json" "$tmp/left-results.json"
cp "$tmp/left-run/.articula/segment.json" "$tmp/segment-stamp.json"
cp "$tmp/left-run/.articula/sample.json" "$tmp/sample-stamp.json"
echo "damaged" > "$tmp/left-run/points.ply"
"$bin/articula" run -i "$tmp/left/phantom.nii.gz" -o "$tmp/left-run" --side left -q
cmp -s "$tmp/segment-stamp.json" "$tmp/left-run/.articula/segment.json" || fail "an intact stage (segment) was redone"
if cmp -s "$tmp/sample-stamp.json" "$tmp/left-run/.articula/sample.json"; then fail "the damaged points.ply was kept"; fi
python3 - "$tmp/left-results.json" "$tmp/left-run/results.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
assert [m["errors"]["rms_mm"] for m in a["models"]] == [m["errors"]["rms_mm"] for m in b["models"]], "results changed"
PY
echo "head isolation: ok"
