#!/usr/bin/env bash
# Scale: `articula fit` then `articula errors` on N points (default 10^6) of a
# noisy ellipsoidal cap (radii 24 / 22.5 / 23 mm, 0.15 mm noise along the
# radius, seeded), with wall time and peak memory of each, and the same with
# --threads 1 for the parallel speed-up. Target: fit + errors <= 30 s and
# <= 1 GB each at 10^6 points.
#   bash bench/scale.sh [build/bin] [scratch dir] [N]
set -euo pipefail
bin=$(cd "${1:-build/bin}" && pwd)
work=${2:-$(mktemp -d)}
n=${3:-1000000}
mkdir -p "$work"
python3 - "$work/cap.csv" "$n" <<'PY'
import math, random, sys
random.seed(3)
with open(sys.argv[1], "w") as f:
    f.write("x,y,z\n")
    for _ in range(int(sys.argv[2])):
        t, p = math.acos(1 - random.uniform(0, 1.3)), random.uniform(0, 2 * math.pi)
        r = 23 + random.gauss(0, 0.15)
        f.write(f"{24 * math.sin(t) * math.cos(p) + r - 23:.4f},{22.5 * math.sin(t) * math.sin(p):.4f},{r * math.cos(t):.4f}\n")
PY
measure() {  # measure LABEL command...: prints LABEL, seconds and peak MB
  local label=$1; shift
  /usr/bin/time -f "%e %M" -o "$work/time.txt" "$@" > /dev/null 2> "$work/$label.log"
  read -r seconds kb < "$work/time.txt"
  echo "$label: ${seconds} s, $((kb / 1024)) MB"
  echo "$seconds" > "$work/$label.s"
}
for threads in 0 1; do
  measure "fit-threads$threads" "$bin/articula" fit -i "$work/cap.csv" -o "$work/fits$threads.json" --force --threads $threads
  measure "errors-threads$threads" "$bin/articula" errors -i "$work/cap.csv" --fits "$work/fits$threads.json" \
    -o "$work/errors$threads" --force --threads $threads
done
cmp "$work/fits0.json" "$work/fits1.json" > /dev/null 2>&1 ||
  python3 - "$work/fits0.json" "$work/fits1.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
for x, y in zip(a["models"], b["models"]):
    assert x["parameters_table_3_2"] == y["parameters_table_3_2"], x["model"] + ": threads change the result"
print("fits identical for every thread count (up to timing fields)")
PY
python3 - "$work" <<'PY'
import sys
w = sys.argv[1]
s = {k: float(open(f"{w}/{k}.s").read()) for k in ("fit-threads0", "errors-threads0", "fit-threads1", "errors-threads1")}
total = s["fit-threads0"] + s["errors-threads0"]
print(f"fit + errors: {total:.1f} s (target <= 30 s); with --threads 1: "
      f"{s['fit-threads1'] + s['errors-threads1']:.1f} s")
PY
