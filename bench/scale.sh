#!/usr/bin/env bash
# Scale: `articula fit` then `articula errors` on N points (default 10^6) of
# each of two noisy caps, seeded, with wall time and peak memory (/usr/bin/time
# -v) of each, and the same with --threads 1 for the parallel speed-up:
#   ellipsoidal:     radii 24 / 22.5 / 23 mm, 0.15 mm noise along the radius;
#   near-spherical:  radii 23 / 22.3 / 23.5 mm, 0.1 mm noise along the radius
#                    (most directions from the centre about as near: the
#                    global searches of points inside are at their hardest).
# Target: fit + errors <= 30 s and <= 1 GB each at 10^6 points, for each cap.
#   bash bench/scale.sh [build/bin] [scratch dir] [N] [caps]
# caps: "ellipsoidal near-spherical" (the default), or either one.
set -euo pipefail
bin=$(cd "${1:-build/bin}" && pwd)
work=${2:-$(mktemp -d)}
n=${3:-1000000}
caps=${4:-ellipsoidal near-spherical}
mkdir -p "$work"
make_cap() {  # make_cap NAME FILE
  python3 - "$1" "$2" "$n" <<'PY'
import math, random, sys
name, path, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
with open(path, "w") as f:
    f.write("x,y,z\n")
    if name == "ellipsoidal":
        random.seed(3)
        for _ in range(n):
            t, p = math.acos(1 - random.uniform(0, 1.3)), random.uniform(0, 2 * math.pi)
            r = 23 + random.gauss(0, 0.15)
            f.write(f"{24 * math.sin(t) * math.cos(p) + r - 23:.4f},{22.5 * math.sin(t) * math.sin(p):.4f},{r * math.cos(t):.4f}\n")
    elif name == "near-spherical":
        random.seed(5)
        a, b, c = 23.0, 22.3, 23.5
        for _ in range(n):
            t, p = math.acos(1 - random.uniform(0, 1.3)), random.uniform(0, 2 * math.pi)
            u = (math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))
            e = random.gauss(0, 0.1)
            f.write(f"{(a + e) * u[0]:.4f},{(b + e) * u[1]:.4f},{(c + e) * u[2]:.4f}\n")
    else:
        sys.exit(f"unknown cap '{name}' (ellipsoidal, near-spherical)")
PY
}
measure() {  # measure LABEL command...: prints LABEL, seconds and peak MB
  local label=$1; shift
  /usr/bin/time -v -o "$work/time.txt" "$@" > /dev/null 2> "$work/$label.log"
  local seconds kb
  seconds=$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, t, ":"); s = 0; for (i = 1; i <= n; ++i) s = s * 60 + t[i]; print s}' "$work/time.txt")
  kb=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$work/time.txt")
  echo "$label: ${seconds} s, $((kb / 1024)) MB"
  echo "$seconds $((kb / 1024))" > "$work/$label.s"
}
for cap in $caps; do
  make_cap "$cap" "$work/$cap.csv"
  for threads in 0 1; do
    measure "$cap-fit-threads$threads" "$bin/articula" fit -i "$work/$cap.csv" -o "$work/$cap-fits$threads.json" \
      --force --threads $threads
    measure "$cap-errors-threads$threads" "$bin/articula" errors -i "$work/$cap.csv" --fits "$work/$cap-fits$threads.json" \
      -o "$work/$cap-errors$threads" --force --threads $threads
  done
  cmp "$work/$cap-fits0.json" "$work/$cap-fits1.json" > /dev/null 2>&1 ||
    python3 - "$work/$cap-fits0.json" "$work/$cap-fits1.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
for x, y in zip(a["models"], b["models"]):
    assert x["parameters_table_3_2"] == y["parameters_table_3_2"], x["model"] + ": threads change the result"
print("fits identical for every thread count (up to timing fields)")
PY
  python3 - "$work" "$cap" <<'PY'
import sys
w, cap = sys.argv[1], sys.argv[2]
s = {k: [float(v) for v in open(f"{w}/{cap}-{k}.s").read().split()]
     for k in ("fit-threads0", "errors-threads0", "fit-threads1", "errors-threads1")}
total = s["fit-threads0"][0] + s["errors-threads0"][0]
peak = max(v[1] for v in s.values())
print(f"{cap}: fit + errors {total:.1f} s (target <= 30 s), peak {peak:.0f} MB (target <= 1024); "
      f"with --threads 1: {s['fit-threads1'][0] + s['errors-threads1'][0]:.1f} s")
PY
done
