#!/usr/bin/env bash
# Robustness of the whole chain on phantoms of known shape: `articula run` on
# a matrix of 64 phantom heads (both sides; NIfTI and DICOM; LPS and RAS
# storage; voxels 0.6-0.8 mm, 1 x 1 x 1.25, 1 x 1 x 2 and 1.5 x 1.5 x 3 mm;
# joint gaps 1.5-5 mm; head radii 17-30 mm; all five models; congruent and
# spherical sockets; normal and osteoporotic bone; fovea pits; both-hips
# pelvis CTs with each side run). Each head is correct (articular points'
# RMS to the true surface <= half the in-plane voxel and >= 95 % of them
# within 1.5 mm), refused (exit != 0), wrong but warned (exit 0, a check of
# the head or its surface warned: not only the side's) or SILENTLY WRONG
# (exit 0, not correct, no such warning). Prints a markdown table of the
# shares per spacing group and one row per head, then the selected model against the true model (a confusion
# matrix, against the drawn model and against the simplest model the drawn
# surface is); writes WORK/robustness.md and WORK/robustness.json.
#   bash bench/robustness.sh [-j N] [--quick] [--fresh] [--ids g0-00,g0-03] [--run-args '--edge-model cortex'] [build/bin] [WORK]
# Needs build/bin/articula and build/bin/bench-score-head (the scorer).
set -euo pipefail
jobs=2 quick=() extra=()
args=()
while (($#)); do
  case $1 in
    -j) jobs=$2; shift 2 ;;
    -j*) jobs=${1#-j}; shift ;;
    --quick) quick=(--quick); shift ;;
    --fresh) extra+=(--fresh); shift ;;
    --ids) extra+=(--ids "$2"); shift 2 ;;
    --run-args) extra+=(--run-args "$2"); shift 2 ;;
    *) args+=("$1"); shift ;;
  esac
done
bin=${args[0]:-build/bin}
work=${args[1]:-$(mktemp -d)}
for exe in articula bench-score-head; do
  [[ -x "$bin/$exe" ]] || { echo "robustness.sh: expected $bin/$exe (build it first)" >&2; exit 2; }
done
exec python3 "$(dirname "$0")/robustness.py" --bin "$bin" --work "$work" -j "$jobs" "${quick[@]}" "${extra[@]}"
