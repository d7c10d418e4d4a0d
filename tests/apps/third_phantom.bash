# Shared by the scripts on the third generator's phantoms
# (bench/third_phantom.py; sourced, not a test itself): the generator, a
# score against its truth and a run that keeps its exit code. Skips the
# test (77) without numpy and scipy.
python3 -c "import numpy, scipy" 2> /dev/null || { echo "no numpy/scipy: skipped"; exit 77; }
gen="$ARTICULA_SOURCE/bench/third_phantom.py"

# score RUN TRUTH SIDE: exit 0 when the run's articular points lie on the true head.
score() {
  python3 - "$1" "$2" "$3" "$ARTICULA_SOURCE/bench" <<'PY'
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

