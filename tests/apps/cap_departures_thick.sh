#!/usr/bin/env bash
# The surface run into bone beyond the head, named apart from the bone's own
# departures: across 2.5 mm slices over a 2 mm gap a correct phantom head's
# pole takes part of the socket's roof (the rays there meet the socket
# cortex's fall, docs/methods.md). Bone goes on beyond it, so it is a
# bone_beyond region and cap_bone_beyond_mm2 warns, not cap_departure_mm2.
# labels: full-size
source "$(dirname "$0")/common.bash"
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
# The page's table says what the region is.
grep -q 'bone beyond (no joint gap seen' "$tmp/thick/report.html" || fail "the page does not name the region with bone beyond"
