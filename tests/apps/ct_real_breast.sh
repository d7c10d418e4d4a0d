#!/usr/bin/env bash
# The real breast radiotherapy planning CT of ../shared/data/ct (lossy JPEG
# 2000, 1.07 mm pixels, 3 mm slices, arms raised) through the whole run:
# the right humeral head reaches beyond the field of view, which its checks
# and the results' reasons name; the left one lies wholly in view and comes
# out a humeral head (a sphere of 20-26 mm radius, its points within the
# 0.95 mm RMS the thesis reports for real joints, on the patient's left).
# Beside ct_real.sh and ct_real_thorax.sh, so that they run side by side.
# labels: full-size
set -euo pipefail
D=${ARTICULA_SHARED_DATA:-}
[[ -d "$D/ct/breast-rt-shoulders-j2k-dicom" ]] || { echo "no shared CT data: skipped"; exit 77; }
source "$(dirname "$0")/common.bash"
for side in right left; do
  "$bin/articula" run -i "$D/ct/breast-rt-shoulders-j2k-dicom" -o "$tmp/breast-$side" --joint shoulder --side "$side" -q \
    2> "$tmp/breast-$side.err" || fail "breast $side: exit $? ($(tail -1 "$tmp/breast-$side.err"))"
  python3 - "$tmp/breast-$side/results.json" "$side" <<'PY'
import json, sys
results, side = json.load(open(sys.argv[1])), sys.argv[2]
qc = results["qc"]
checks = {c["name"]: c for c in qc["checks"]}
sphere = next(m for m in results["models"] if m["model"] == "sphere")
radius, rms, centre = sphere["parameters"]["a_mm"], sphere["errors"]["rms_mm"], results["head_center_mm"]
print(f"breast {side}: qc {qc['status']}, sphere radius {radius:.2f} mm, RMS {rms:.3f} mm, "
      f"centre x {centre[0]:.1f} mm; " + "; ".join(qc.get("reasons", [])))
assert results["selected_model"] not in results["selection"]["undetermined"], results["selection"]
clipped = ("head_outside_volume_share", "head_beyond_fov_relative")
if side == "right":
    assert qc["status"] != "pass", qc["status"]
    for name in clipped:
        assert checks[name]["status"] in ("warn", "fail"), checks[name]
    assert any("field of view clips the head" in r for r in qc["reasons"]), qc["reasons"]
    assert centre[0] < 0, centre  # LPS: the patient's right at negative x
else:
    for name in clipped:
        assert checks[name]["status"] == "pass", checks[name]
    assert 20 <= radius <= 26, radius
    assert rms < 0.95, rms
    assert not any("field of view" in r for r in qc["reasons"]), qc["reasons"]
    assert centre[0] > 0, centre
PY
done
echo "real breast radiotherapy CT: ok"
