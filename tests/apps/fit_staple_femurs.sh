#!/usr/bin/env bash
# Real data: the femoral heads of the two STAPLE femurs (whole-bone STL).
# articula-sample cuts out the head (CGAL RANSAC sphere, then the connected
# patch), articula-fit fits the hierarchy. Expected (../shared/data/README.md):
# sphere radius 20-28 mm (quick fits gave 22.6-23.0 mm), and the RMS ordered
# sphere >= ellipsoid >= superellipsoid >= superovoid, ovoid >= superovoid.
source "$(dirname "$0")/common.bash"
data=${ARTICULA_SHARED_DATA:?}/meshes/femur
[ -d "$data" ] || { echo "no shared data at $data: skipped"; exit 77; }
for femur in LHDL_CT_femur_r TLEM2_femur_r; do
  "$bin/articula-sample" -i "$data/$femur.stl" -o "$tmp/$femur.ply" --ball-radius 1 --quiet
  "$bin/articula-fit" -i "$tmp/$femur.ply" -o "$tmp/$femur.json" --quiet
  python3 - "$tmp/$femur.json" <<'PY'
import json, sys
fits = {m["model"]: m for m in json.load(open(sys.argv[1]))["models"]}
rms = {k: m["rms_mm"] for k, m in fits.items()}
r = fits["sphere"]["radii_mm"][0]
assert 20 <= r <= 28, f"sphere radius {r}"
assert 22.0 <= r <= 23.8, f"sphere radius {r} far from the 22.6-23.0 mm of the data's README"
tol = 1e-9
assert rms["sphere"] + tol >= rms["ellipsoid"] and rms["ellipsoid"] + tol >= rms["superellipsoid"], rms
assert rms["superellipsoid"] + tol >= rms["superovoid"] and rms["ovoid"] + tol >= rms["superovoid"], rms
assert rms["sphere"] < 0.6, rms
print(sys.argv[1], "sphere radius", round(r, 3), "rms", {k: round(v, 4) for k, v in rms.items()})
PY
done
