#!/usr/bin/env bash
# articula run on phantoms of a third, independent generator
# (bench/third_phantom.py) that used to come out silently wrong:
# - both hips with the field of view shifted 60 mm to the left and the body
#   cut at its edges (no air), 1.5 mm slices: the right head is out of view,
#   and a rounded corner of the sacrum was reported as the right femoral
#   head (a warning only); it must be refused, and the left head, 30 mm from
#   the field's middle, found (it was refused as too near the midline);
# - a thin, faint cortex (0.6 mm at 500 HU over 100 HU textured cancellous
#   bone): the bone window cut the label 3 mm inside the dome, and the head
#   was reported with its checks passing; it must be refused or found on
#   its true surface.
# labels: full-size
source "$(dirname "$0")/common.bash"
py=/usr/bin/python3  # Debian's, with python3-numpy and python3-scipy
"$py" -c "import numpy, scipy" 2> /dev/null || { echo "no numpy/scipy: skipped"; exit 77; }
gen="$ARTICULA_SOURCE/bench/third_phantom.py"

# score RUN TRUTH SIDE: exit 0 when the run's articular points lie on the true head.
score() {
  "$py" - "$1" "$2" "$3" "$ARTICULA_SOURCE/bench" <<'PY'
import json, sys
import numpy as np
run, truth, side, bench = sys.argv[1:5]
sys.path.insert(0, bench)
from third_phantom import head_distances
t = json.load(open(truth))
d = head_distances(f"{run}/errors/errors.csv", truth, side)
rms = float(np.sqrt((d ** 2).mean()))
print(f"{run}: RMS {rms:.3f} mm to the true head, {100 * (np.abs(d) <= 1.5).mean():.0f} % within 1.5 mm")
sys.exit(0 if rms <= 0.5 * t["spacing_mm"][0] and (np.abs(d) <= 1.5).mean() >= 0.95 else 1)
PY
}

# run NAME SIDE: the run's exit code in $rc, its stderr in $tmp/NAME-SIDE.err.
run() {
  set +e
  "$bin/articula" run -i "$tmp/$1.nii.gz" -o "$tmp/$1-$2" --joint hip --side "$2" --threads 2 -q 2> "$tmp/$1-$2.err"
  rc=$?
  set -e
}

"$py" "$gen" out="$tmp/shifted" joint=hip both=1 side=left seed=410 R=24 gap=2.5 air=0 fov=135,70,65 fov_shift=60,0,0 \
  spacing=0.8,0.8,1.5 > /dev/null
run shifted right
[ "$rc" -eq 1 ] || fail "the right hip, out of view, was not refused (exit $rc): $(score "$tmp/shifted-right" "$tmp/shifted.json" right)"
grep -q "no femoral head" "$tmp/shifted-right.err" || fail "refused without naming the reason: $(cat "$tmp/shifted-right.err")"
run shifted left
[ "$rc" -eq 0 ] || fail "the left head was not found (exit $rc): $(cat "$tmp/shifted-left.err")"
score "$tmp/shifted-left" "$tmp/shifted.json" left || fail "the left head came out wrong"

"$py" "$gen" out="$tmp/faint" joint=hip side=left seed=109 R=21 gap=2 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 \
  spacing=0.8,0.8,1.25 noise=20 > /dev/null
run faint left
if [ "$rc" -eq 0 ]; then
  score "$tmp/faint-left" "$tmp/faint.json" left || fail "the faint head came out wrong with exit 0"
else
  [ "$rc" -eq 1 ] || fail "the faint head: exit $rc"
  grep -q "qc\|no femoral head" "$tmp/faint-left.err" || fail "refused without a reason: $(cat "$tmp/faint-left.err")"
fi
echo "head isolation on the third generator: ok"
