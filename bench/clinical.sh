#!/usr/bin/env bash
# Clinical failure modes: `articula run` on 6 phantom heads (the five
# models; radii 18-28 mm; right and left; 0.6 x 0.6 x 1 to 1 x 1 x 3 mm
# voxels; one in a both-hips pelvis CT) x 43 cases of what clinical CT adds:
# none; a flattened dome (0.1, 0.25 of the radius); osteophytes (1.5, 3 mm);
# cysts; a narrowed joint (0.8, 0.5 mm); the field of view cut at 0, 10, 25
# and 50 % of the radius from each of the six faces; a screw in the neck, a
# stem in the shaft; soft and sharp kernels; a contrast vessel; the table;
# slices twice as thick as their spacing (at most 5 mm); low dose (noise 60
# and 100 HU), also over an osteoporotic head's thin cortex. Each case is right (the articular points' RMS to the true
# surface <= half the in-plane voxel and >= 95 % within 1.5 mm), flagged (not
# right, a check of the head warned or failed, named), refused (exit != 0,
# with its reason) or SILENTLY WRONG (not right, no such check). Prints
# markdown tables (per mode and strength; the field-of-view cuts per face
# and depth; the cases not right); writes WORK/clinical.md (with every case)
# and WORK/clinical.json.
#   bash bench/clinical.sh [-j N] [--quick] [--ids h0,h2-05] [--modes 'FOV cut,metal'] [build/bin] [WORK]
# (python3 bench/clinical.py --work WORK --tables-only writes the tables again.)
# Needs build/bin/articula and build/bin/bench-score-head (the scorer).
set -euo pipefail
jobs=1 extra=()
args=()
while (($#)); do
  case $1 in
    -j) jobs=$2; shift 2 ;;
    -j*) jobs=${1#-j}; shift ;;
    --quick) extra+=(--quick); shift ;;
    --ids) extra+=(--ids "$2"); shift 2 ;;
    --modes) extra+=(--modes "$2"); shift 2 ;;
    *) args+=("$1"); shift ;;
  esac
done
bin=${args[0]:-build/bin}
work=${args[1]:-$(mktemp -d)}
for exe in articula bench-score-head; do
  [[ -x "$bin/$exe" ]] || { echo "clinical.sh: expected $bin/$exe (build it first)" >&2; exit 2; }
done
exec python3 "$(dirname "$0")/clinical.py" --bin "$bin" --work "$work" -j "$jobs" "${extra[@]}"
