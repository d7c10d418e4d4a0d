#!/usr/bin/env bash
# The real-CT targets on ../shared/data/ct/thorax-shoulders-dicom
# (512 x 512 x 141), right humeral head, found automatically:
#   segment + mesh + sample <= 20 s wall on 2 cores and <= 2 GB peak memory;
#   `articula run` (segment -> ... -> report) <= 30 s wall.
# Each is run REPEATS times (default 3); prints the median wall time per
# stage, the total, the peak resident memory of any stage and the ratio to
# the budget (a ratio <= 1 meets the target).
#   bash bench/real_ct.sh [build/bin] [scratch dir]
set -euo pipefail
bin=$(cd "${1:-build/bin}" && pwd)
work=${2:-$(mktemp -d)}
data=${ARTICULA_SHARED_DATA:-$(dirname "$0")/../../shared/data}
series=$data/ct/thorax-shoulders-dicom
[[ -d "$series" ]] || { echo "no $series: set ARTICULA_SHARED_DATA" >&2; exit 77; }
repeats=${REPEATS:-3}
mkdir -p "$work"
timed() {  # timed LABEL command...: appends "LABEL seconds kilobytes" to $work/times
  local label=$1; shift
  /usr/bin/time -f "$label %e %M" -a -o "$work/times" "$@" -q --force
}
rm -f "$work/times"
for r in $(seq 1 "$repeats"); do
  timed segment "$bin/articula-segment" -i "$series" -o "$work/label.nii.gz" --joint shoulder --side right
  timed mesh "$bin/articula-mesh" -i "$work/label.nii.gz" -o "$work/bone.vtp" --ct "$series"
  timed sample "$bin/articula-sample" -i "$work/bone.vtp" -o "$work/points.ply"
  # Exit 1 is this head's verdict (the field of view clips it: a fail of its
  # checks), with every output written.
  timed run "$bin/articula" run -i "$series" -o "$work/run" --joint shoulder --side right || [ $? -eq 1 ]
done
python3 - "$work/times" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1]) if l.strip() and not l.startswith("Command")]
t, m = {}, {}
for label, sec, kb in rows:
    t.setdefault(label, []).append(float(sec)); m[label] = max(m.get(label, 0), int(kb))
med = {k: statistics.median(v) for k, v in t.items()}
chain = med["segment"] + med["mesh"] + med["sample"]
peak = max(m["segment"], m["mesh"], m["sample"]) / 1024**2
for k in ("segment", "mesh", "sample", "run"):
    print(f"{k:8s} median {med[k]:6.2f} s over {len(t[k])} runs, peak {m[k] / 1024:7.0f} MB")
print(f"segment + mesh + sample: {chain:.2f} s (ratio {chain / 20:.2f} of the 20 s budget), "
      f"peak {peak:.2f} GB (ratio {peak / 2:.2f} of 2 GB)")
print(f"articula run: {med['run']:.2f} s (ratio {med['run'] / 30:.2f} of the 30 s budget), peak {m['run'] / 1024**2:.2f} GB")
PY
