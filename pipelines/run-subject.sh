#!/usr/bin/env bash
# Chains the stage apps on one CT (a DICOM folder or a NIfTI/NRRD/MHA file),
# as a user would in a shell. Outputs in OUTDIR; coordinates LPS mm.
#   pipelines/run-subject.sh INPUT OUTDIR [hip|shoulder] [left|right] [auto|cortex|steepest]
# The last picks the mesh stage's edge model (--edge-model; default auto).
# Set ARTICULA_BIN to the folder of the executables (default: build/bin).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 INPUT OUTDIR [hip|shoulder] [left|right] [auto|cortex|steepest]" >&2
  exit 2
fi
input=$1 out=$2 joint=${3:-hip} side=${4:-right} edge_model=${5:-auto}
bin=${ARTICULA_BIN:-$(cd "$(dirname "$0")/.." && pwd)/build/bin}
mkdir -p "$out"
"$bin/articula-segment" -i "$input" -o "$out/label.nii.gz" --joint "$joint" --side "$side" --force
"$bin/articula-mesh"    -i "$out/label.nii.gz" -o "$out/bone.vtp" --ct "$input" --edge-model "$edge_model" --force
"$bin/articula-sample"  -i "$out/bone.vtp" -o "$out/points.ply" --force
"$bin/articula-fit"     -i "$out/points.ply" -o "$out/fits.json" --grid "$out/label.nii.gz" --force
"$bin/articula-errors"  -i "$out/points.ply" --fits "$out/fits.json" -o "$out/errors" --force
"$bin/articula-report"  -i "$out" --ct "$input" --joint "$joint" --side "$side" --force
echo "done: $out/results.json"
