#!/usr/bin/env bash
# Batch scaling: 8 phantom subjects, `articula batch -j 1` versus
# `-j 2` (target: -j 2 <= 0.6x the time of -j 1), and a rerun of the finished
# batch (target: <= 0.3x the first run). Prints the times and ratios.
#   bash bench/batch_scaling.sh [build/bin] [scratch dir]
set -euo pipefail
bin=$(cd "${1:-build/bin}" && pwd)
work=${2:-$(mktemp -d)}
mkdir -p "$work"
models=(sphere ellipsoid superellipsoid ovoid superovoid sphere ellipsoid superovoid)
echo "subject,input,joint,side" > "$work/study.csv"
for i in $(seq 1 8); do
  "$bin/articula" phantom -o "$work/data/s$i" --seed $((100 + i)) --model "${models[$((i - 1))]}" --no-dicom --quiet --force
  echo "s$i,data/s$i/phantom.nii.gz,hip,right" >> "$work/study.csv"
done
now() { date +%s.%N; }
t0=$(now); "$bin/articula" batch "$work/study.csv" -o "$work/j1" -j 1 --quiet; t1=$(now)
"$bin/articula" batch "$work/study.csv" -o "$work/j2" -j 2 --quiet; t2=$(now)
"$bin/articula" batch "$work/study.csv" -o "$work/j2" -j 2 --quiet; t3=$(now)
python3 - "$t0" "$t1" "$t2" "$t3" <<'PY'
import sys
t0, t1, t2, t3 = map(float, sys.argv[1:])
j1, j2, rerun = t1 - t0, t2 - t1, t3 - t2
print(f"8 subjects: -j 1 {j1:.1f} s, -j 2 {j2:.1f} s (ratio {j2 / j1:.2f}, target <= 0.6); "
      f"rerun {rerun:.2f} s (ratio {rerun / j2:.3f} of the -j 2 run, target <= 0.3)")
PY
cmp "$work/j1/study.csv" "$work/j2/study.csv" && echo "study.csv identical for -j 1 and -j 2"
