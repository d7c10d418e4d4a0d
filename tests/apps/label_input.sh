#!/usr/bin/env bash
# An outside segmentation as input: `articula run --label` with the
# phantom's own femur label (label 1 of femur_truth.nii.gz) finds the head
# the built-in search finds; a label in another grid, a value no voxel holds
# and a missing file are refused by name.
# fixtures: sphere
# labels: full-size
source "$(dirname "$0")/common.bash"
P=${ARTICULA_FIXTURES:?}/sphere
"$bin/articula" run -i "$P/phantom/phantom.nii.gz" -o "$tmp/labelled" --label "$P/phantom/femur_truth.nii.gz" \
  --label-value 1 --quiet
python3 - "$P/run/results.json" "$tmp/labelled/results.json" "$tmp/labelled/label.nii.gz.json" <<'PY'
import json, math, sys
plain, labelled, segment = (json.load(open(p)) for p in sys.argv[1:4])
def sphere(results):
    p = next(m for m in results["models"] if m["model"] == "sphere")["parameters"]
    return [p["t1_mm"], p["t2_mm"], p["t3_mm"]], p["a_mm"]
(c0, r0), (c1, r1) = sphere(plain), sphere(labelled)
print(f"with the label: centre {math.dist(c0, c1):.4f} mm from the search's, radius {r1:.3f} vs {r0:.3f} mm; "
      f"qc {labelled['qc']['status']}")
assert math.dist(c0, c1) < 0.05 and abs(r1 - r0) < 0.05, (c0, c1, r0, r1)
assert labelled["qc"]["status"] == "pass", labelled["qc"]
assert segment["label"].endswith("femur_truth.nii.gz") and segment["side_check"] == "the label's bone", segment
PY
# The same label on another grid (its voxels 1.1 times as large): refused, both grids named.
python3 - "$P/phantom/femur_truth.nii.gz" "$tmp/other-grid.nii.gz" <<'PY'
import gzip, struct, sys
b = bytearray(gzip.open(sys.argv[1]).read())
pixdim = struct.unpack_from("<3f", b, 80)
struct.pack_into("<3f", b, 80, *(1.1 * v for v in pixdim))
for row in range(3):  # the sform's columns too, or the header places its voxels two ways
    at = 280 + 16 * row
    struct.pack_into("<3f", b, at, *(1.1 * v for v in struct.unpack_from("<3f", b, at)))
gzip.open(sys.argv[2], "wb").write(bytes(b))
PY
expect_rc 3 "$bin/articula" run -i "$P/phantom/phantom.nii.gz" -o "$tmp/refused" --label "$tmp/other-grid.nii.gz"
grep -q "expected a label map in the CT's grid (.*), found .*resample it onto the CT" "$tmp/err" ||
  fail "a label on another grid: $(cat "$tmp/err")"
expect_rc 3 "$bin/articula" run -i "$P/phantom/phantom.nii.gz" -o "$tmp/refused" --label "$P/phantom/femur_truth.nii.gz" --label-value 7
grep -q "no voxel holds the value 7" "$tmp/err" || fail "an absent label value: $(cat "$tmp/err")"
expect_rc 3 "$bin/articula" run -i "$P/phantom/phantom.nii.gz" -o "$tmp/refused" --label "$tmp/missing.nii.gz"
grep -q "missing.nii.gz" "$tmp/err" || fail "a missing label: $(cat "$tmp/err")"
[ ! -e "$tmp/refused/label.nii.gz" ] || fail "a refused label left a segmentation"
