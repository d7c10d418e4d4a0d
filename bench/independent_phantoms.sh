#!/usr/bin/env bash
# `articula run` on hip CT phantoms from a second, independent generator
# (bench/independent_phantom.py: other geometry, tissue levels, a body
# outline in air, a field of view centred on the head), scored against their
# truth: the selected model's centre error and the articular points' radial
# distance to the true head (mean signed, RMS, share within 1.5 mm).
#   bash bench/independent_phantoms.sh [build/bin] [scratch dir]
set -uo pipefail
bin=$(cd "${1:-build/bin}" && pwd)
work=${2:-$(mktemp -d)}
here=$(cd "$(dirname "$0")" && pwd)
py=${PYTHON:-/usr/bin/python3}  # Debian's, with python3-numpy and python3-scipy
mkdir -p "$work"
cd "$work"
cases=(
  "h1 right R=23 gap=2"
  "v1 left R=20 gap=1.5 seed=2"
  "v2 right R=17 gap=2.5 spacing=1.0,1.0,1.25 seed=3"
  "v3 left R=29 gap=3 axes=1.05,0.97,1.0 seed=4"
  "v4 right R=25 gap=1.5 cortex=0.8 cort_hu=800 trab_hu=200 seed=5"
  "v5 right R=22 gap=2 spacing=0.6,0.6,0.6 blur=0.5 seed=6"
)
echo "| case | side | options | exit | qc | selected | centre error (mm) | mean signed (mm) | RMS (mm) | within 1.5 mm |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for c in "${cases[@]}"; do
  set -- $c
  name=$1 side=$2; shift 2
  [ -e "$name.nii.gz" ] || "$py" "$here/independent_phantom.py" out="$work/$name" side="$side" "$@" > /dev/null
  "$bin/articula" run -i "$name.nii.gz" -o "run-$name" --joint hip --side "$side" --threads 1 --quiet --force 2> "run-$name.err"
  rc=$?
  "$py" - "$work/run-$name" "$work/$name.json" "$name" "$side" "$*" "$rc" <<'PY'
import csv, json, math, sys
run, truth, name, side, options, rc = sys.argv[1:7]
if rc != "0":
    print(f"| {name} | {side} | {options} | {rc} | | | | | | |"); sys.exit()
t = json.load(open(truth)); r = json.load(open(run + "/results.json"))
c, rad = t["head_center_mm"], t["radii_mm"]
d = []
for row in csv.DictReader(open(run + "/errors/errors.csv")):
    p = [float(row[k]) - c[i] for i, k in enumerate(("x_mm", "y_mm", "z_mm"))]
    q = math.sqrt(sum((p[i] / rad[i]) ** 2 for i in range(3)))
    n = math.sqrt(sum(v * v for v in p))
    d.append(n - n / q)  # radial distance to the true head
sel = next(m for m in r["models"] if m["model"] == r["selected_model"])
ce = math.dist([sel["parameters"][k] for k in ("t1_mm", "t2_mm", "t3_mm")], c)
mean = sum(d) / len(d); rms = math.sqrt(sum(v * v for v in d) / len(d)); within = sum(abs(v) <= 1.5 for v in d) / len(d)
print(f"| {name} | {side} | {options} | 0 | {r['qc']['status']} | {r['selected_model']} | {ce:.2f} | {mean:+.3f} | {rms:.3f} | {100 * within:.0f} % |")
PY
done
