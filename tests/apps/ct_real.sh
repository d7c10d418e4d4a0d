#!/usr/bin/env bash
# The real CTs of ../shared/data/ct: segment + mesh + sample of a joint head
# found automatically (no seed point): the right femoral head of the 3 mm hip
# NIfTI, the right humeral head of the thorax DICOM series and the complete
# left humeral head of the lossy JPEG 2000 breast-RT series. The articular
# sphere must be that of an adult joint head (18-30 mm), on the asked side,
# and agree with the search's own sphere. The abdomen series holds no joint
# head: exit code 1.
# labels: full-size
set -euo pipefail
D=${ARTICULA_SHARED_DATA:-}
[[ -d "$D/ct/hip-3mm-nifti" && -d "$D/ct/thorax-shoulders-dicom" ]] || { echo "no shared CT data: skipped"; exit 77; }
source "$(dirname "$0")/common.bash"
B=$bin
T=$tmp
run() {  # run NAME INPUT JOINT SIDE [WARNINGS_ALLOWED]
  local name=$1 input=$2 joint=$3 side=$4 warnings_allowed=${5:-no}
  "$B/articula-segment" -i "$input" -o "$T/$name.nii.gz" --joint "$joint" --side "$side" -q
  "$B/articula-mesh" -i "$T/$name.nii.gz" -o "$T/$name.vtp" -q
  "$B/articula-sample" -i "$T/$name.vtp" -o "$T/$name.ply" --json -q > "$T/$name.json"
  python3 - "$T/$name.json" "$T/$name.nii.gz.json" "$name" "$side" "$warnings_allowed" <<'PY'
import json, math, sys
s, seg, name, side = json.load(open(sys.argv[1])), json.load(open(sys.argv[2])), sys.argv[3], sys.argv[4]
r, c = s["sphere"]["radius_mm"], s["sphere"]["center_mm"]
print(f"{name}: sphere radius {r:.2f} mm, RMS {s['sphere']['rms_mm']:.2f} mm, centre {[round(v, 1) for v in c]}, "
      f"{s['reduced_points']} of {s['selected_points']} points; search: centre "
      f"{[round(v, 1) for v in seg['head_center_mm']]}, radius {seg['search_radius_mm']:.1f} mm")
assert 18 <= r <= 30, r
assert s["sphere"]["rms_mm"] < 1.0, s["sphere"]["rms_mm"]
assert (c[0] < 0) == (side == "right"), "the right side is -x in LPS"
assert math.dist(c, seg["head_center_mm"]) < 8, "the articular sphere is not the search's head"
assert sys.argv[5] == "yes" or seg["warnings"] == [], seg["warnings"]
PY
}
run hip "$D/ct/hip-3mm-nifti/example_ct.nii.gz" hip right
run shoulder "$D/ct/thorax-shoulders-dicom" shoulder right
if [[ -d "$D/ct/breast-rt-shoulders-j2k-dicom" ]]; then
  # Lossy JPEG 2000 and osteoporotic: the label may be a thin shell (warned).
  run breast "$D/ct/breast-rt-shoulders-j2k-dicom" shoulder left yes
fi
if [[ -d "$D/ct/abdomen-j2k-dicom" ]]; then
  expect_rc 1 "$B/articula-segment" -i "$D/ct/abdomen-j2k-dicom" -o "$T/abdomen.nii.gz"
  grep -q "no femoral head found" "$tmp/err" || fail "abdomen: $(cat "$tmp/err")"
  [[ ! -e "$T/abdomen.nii.gz" ]] || fail "abdomen: a label was written"
fi
echo "real CTs: ok"
