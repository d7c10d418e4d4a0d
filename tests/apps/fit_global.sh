#!/usr/bin/env bash
# Superellipsoid heads whose radii lie within 10 % of each other (phantom
# seeds 7 and 12: radii 24.9 / 22.7 / 25.1 mm, exponents 2.50 / 2.03 /
# 2.09 for seed 7): from the ellipsoid's axis labelling alone the
# superellipsoid ended at 0.30 mm RMS and the run selected the superovoid
# (a superellipsoid under another labelling). The run selects the
# superellipsoid, which fits within 0.02 mm of the superovoid. The edges
# on the steepest fall: the test is of the fit's start, and the
# blurred-cortex model would double its time.
# labels: full-size
source "$(dirname "$0")/common.bash"
for seed in 7 12; do
  "$bin/articula" phantom -o "$tmp/p$seed" --seed "$seed" --no-dicom -q
  "$bin/articula" run -i "$tmp/p$seed/phantom.nii.gz" -o "$tmp/r$seed" --edge-model steepest -q
  python3 - "$tmp/p$seed/truth.json" "$tmp/r$seed/results.json" <<'PY'
import json, sys
truth, r = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
rms = {m["model"]: m["errors"]["rms_mm"] for m in r["models"]}
print(f"{truth['model']} head: selected {r['selected_model']}, RMS {rms}")
assert truth["model"] == "superellipsoid"
assert r["selected_model"] == "superellipsoid", r["selected_model"]
assert rms["superellipsoid"] <= rms["superovoid"] + 0.02, rms
assert rms["superellipsoid"] < 0.8 * rms["ellipsoid"], rms
PY
done
echo "global fit: ok"
