#!/usr/bin/env bash
# Slices reconstructed thicker than their spacing (3 mm every 1.5 mm): the
# phantom's DICOM series states it in Slice Thickness (0018,0050), and the
# run takes it as what a voxel averages over across the slices; a NIfTI file
# holds no thickness, which --slice-thickness gives. Both runs find the head;
# a thickness beyond the option's range is refused (exit 2).
source "$(dirname "$0")/common.bash"

"$bin/articula" phantom -o "$tmp/p" --seed 9 --spacing 1.2,1.2,1.5 --slice-thickness 3 --quiet
"$bin/articula" run -i "$tmp/p/dicom" -o "$tmp/dicom" --joint hip --side right -q ||
  fail "the run on the DICOM series failed"
"$bin/articula" run -i "$tmp/p/phantom.nii.gz" -o "$tmp/nifti" --joint hip --side right --slice-thickness 3 -q ||
  fail "the run on the NIfTI file failed"
python3 - "$tmp" <<'PY'
import json, math, sys
tmp = sys.argv[1]
truth = json.load(open(f"{tmp}/p/truth.json"))
for run, stated in (("dicom", 3.0), ("nifti", None)):
    label = json.load(open(f"{tmp}/{run}/label.nii.gz.json"))
    assert label["slice_thickness_stated_mm"] == stated, (run, label["slice_thickness_stated_mm"])
    assert abs(label["voxel_extent_mm"][2] - (stated or 1.5)) < 1e-9, (run, label["voxel_extent_mm"])
    edges = json.load(open(f"{tmp}/{run}/bone.vtp.json"))["ct_edges"]
    assert edges["edge_model"] == "cortex", edges
    assert abs(edges["slice_thickness_mm"] - 3.0) < 1e-9, (run, edges["slice_thickness_mm"])
    r = json.load(open(f"{tmp}/{run}/results.json"))
    sphere = next(m for m in r["models"] if m["model"] == "sphere")
    err = math.dist([sphere["parameters"][k] for k in ("t1_mm", "t2_mm", "t3_mm")], truth["head_center_mm"])
    print(f"{run}: sphere centre {err:.2f} mm from the truth, qc {r['qc']['status']}")
    assert err < 1.0, err
    assert r["qc"]["status"] in ("pass", "warn"), r["qc"]
PY
expect_rc 2 "$bin/articula" run -i "$tmp/p/phantom.nii.gz" -o "$tmp/bad" --joint hip --side right --slice-thickness 30
grep -q "slice-thickness" "$tmp/err" || fail "the bad thickness is not named: $(cat "$tmp/err")"
echo "slice thickness: ok"
