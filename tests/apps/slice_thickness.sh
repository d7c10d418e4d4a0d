#!/usr/bin/env bash
# Slices reconstructed thicker than their spacing (3 mm every 1.5 mm): the
# phantom's DICOM series states it in Slice Thickness (0018,0050), and the
# run takes it as what a voxel averages over across the slices, and finds
# the head; a NIfTI file holds no thickness, which the mesh stage's
# --slice-thickness gives; a thickness beyond its range is refused (exit 2).
# The point-spread is given (the phantom's), so that the stages skip its
# estimate, which takes most of their time and is tested elsewhere.
source "$(dirname "$0")/common.bash"

"$bin/articula" phantom -o "$tmp/p" --seed 9 --spacing 1.2,1.2,1.5 --slice-thickness 3 --quiet
spread=(--point-spread 0.5 --slice-point-spread 0.5)
"$bin/articula" run -i "$tmp/p/dicom" -o "$tmp/dicom" --joint hip --side right "${spread[@]}" -q ||
  fail "the run on the DICOM series failed"
"$bin/articula" mesh -i "$tmp/dicom/label.nii.gz" --ct "$tmp/p/phantom.nii.gz" -o "$tmp/nifti.vtp" "${spread[@]}" \
  --slice-thickness 3 -q || fail "the mesh stage on the NIfTI file failed"
python3 - "$tmp" <<'PY'
import json, math, sys
tmp = sys.argv[1]
truth = json.load(open(f"{tmp}/p/truth.json"))
label = json.load(open(f"{tmp}/dicom/label.nii.gz.json"))
assert label["slice_thickness_stated_mm"] == 3.0, label["slice_thickness_stated_mm"]
assert label["voxel_extent_mm"][2] == 3.0, label["voxel_extent_mm"]
for mesh in ("dicom/bone.vtp.json", "nifti.vtp.json"):
    edges = json.load(open(f"{tmp}/{mesh}"))["ct_edges"]
    assert edges["edge_model"] == "cortex", (mesh, edges)
    assert abs(edges["slice_thickness_mm"] - 3.0) < 1e-9, (mesh, edges["slice_thickness_mm"])
r = json.load(open(f"{tmp}/dicom/results.json"))
sphere = next(m for m in r["models"] if m["model"] == "sphere")
err = math.dist([sphere["parameters"][k] for k in ("t1_mm", "t2_mm", "t3_mm")], truth["head_center_mm"])
print(f"sphere centre {err:.2f} mm from the truth, qc {r['qc']['status']}")
assert err < 1.0, err
assert r["qc"]["status"] in ("pass", "warn"), r["qc"]
PY
expect_rc 2 "$bin/articula" mesh -i "$tmp/dicom/label.nii.gz" --ct "$tmp/p/phantom.nii.gz" -o "$tmp/bad.vtp" \
  --slice-thickness 30
grep -q "slice-thickness" "$tmp/err" || fail "the bad thickness is not named: $(cat "$tmp/err")"
echo "slice thickness: ok"
