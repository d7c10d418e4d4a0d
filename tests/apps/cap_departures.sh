#!/usr/bin/env bash
# What the articular selection leaves out, measured: a phantom head whose
# weight-bearing dome is flattened by 12 % of its radius departs from the
# selected model over the flattened part deeper than the threshold (for a
# cap cut by a plane, area grows with depth: the truth's area times
# (depth - threshold) / depth), superiorly, and the check warns; the same
# head unflattened departs nowhere by the finding depth, and the check passes;
# a correct head whose pole took the socket's roof across thick slices is
# named by cap_bone_beyond_mm2 instead.
# At 0.8 mm voxels, on the default edges (the blurred-cortex model): across
# 1.5 mm slices the model's departure comes out 0.26 mm shallow and its area
# a fifth short (docs/benchmarks.md, "Surface bias by voxel size").
# labels: full-size
source "$(dirname "$0")/common.bash"
for shape in flat plain; do
  extra=()
  [ "$shape" = flat ] && extra=(--flattened-dome 0.12)
  "$bin/articula" phantom -o "$tmp/$shape-ct" --no-dicom --seed 21 --spacing 0.8,0.8,0.8 "${extra[@]}" --quiet
  "$bin/articula" run -i "$tmp/$shape-ct/phantom.nii.gz" --joint hip --side right -o "$tmp/$shape" --quiet
done
python3 - "$tmp" <<'PY'
import json, sys
tmp = sys.argv[1]
def read(shape):
    results = json.load(open(f"{tmp}/{shape}/results.json"))
    check = next(c for c in results["qc"]["checks"] if c["name"] == "cap_departure_mm2")
    return results["cap_departures"], check
flat, flat_check = read("flat")
truth = json.load(open(f"{tmp}/flat-ct/truth.json"))["departures"][0]
t, h = flat["threshold_mm"], truth["max_depth_mm"]
expected = truth["area_mm2"] * (h - t) / h
dome = flat["regions"][0]
print(f"flattened: {dome['kind']} {dome['area_mm2']:.0f} mm2 (expected {expected:.0f}), {dome['depth_mm']:.2f} mm deep "
      f"(truth {h:.2f}), {dome['where']}; check {flat_check['status']}")
assert dome["kind"] == "inward" and dome["where"].startswith("superior"), dome
assert abs(dome["area_mm2"] - expected) < 0.15 * expected, (dome, expected)
assert h - 0.2 < dome["depth_mm"] < h + 0.8, (dome, h)
assert flat_check["status"] == "warn" and flat_check["value"] == dome["area_mm2"], flat_check
plain, plain_check = read("plain")
print(f"plain: regions {[(r['kind'], round(r['area_mm2']), round(r['depth_mm'], 2)) for r in plain['regions']]}; "
      f"check {plain_check['status']}")
assert plain_check["status"] == "pass" and all(r["depth_mm"] < 2 for r in plain["regions"]), plain
PY
# Across 2.5 mm slices over a 2 mm gap a correct head's pole takes part of
# the socket's roof (the rays there meet the socket cortex's fall): bone
# goes on beyond it, so it is named the surface run into bone, not a
# departure of the head.
"$bin/articula" phantom -o "$tmp/thick-ct" --no-dicom --seed 305 --exact --model superovoid --radius 20 \
  --spacing 0.9,0.9,2.5 --gap 2.0 --quiet
"$bin/articula" run -i "$tmp/thick-ct/phantom.nii.gz" --joint hip --side right -o "$tmp/thick" --quiet
python3 - "$tmp/thick/results.json" <<'PY'
import json, sys
results = json.load(open(sys.argv[1]))
checks = {c["name"]: c for c in results["qc"]["checks"]}
regions = results["cap_departures"]["regions"]
print(f"thick slices: regions {[(r['kind'], round(r['area_mm2']), round(r['depth_mm'], 1), r['where']) for r in regions]}")
roof = regions[0]
assert roof["kind"] == "bone_beyond" and roof["where"].startswith("superior") and roof["area_mm2"] > 100, roof
assert checks["cap_bone_beyond_mm2"]["status"] == "warn" and checks["cap_departure_mm2"]["status"] == "pass", checks
PY
# The page lists the region; Slicer gets it as a landmark.
grep -q '<section id="departures">' "$tmp/flat/report.html" || fail "no departures section on the page"
grep -q '"label": "departure_1 (inward' "$tmp/flat/head.mrk.json" || fail "no departure landmark in head.mrk.json"
