#!/usr/bin/env bash
# The real CTs of ../shared/data/ct: segment + mesh + sample of a joint head
# found automatically (no seed point): the right femoral head of the 3 mm hip
# NIfTI, the right humeral head of the thorax DICOM series and the complete
# left humeral head of the lossy JPEG 2000 breast-RT series. The articular
# sphere must be that of an adult joint head (18-30 mm), on the asked side,
# and agree with the search's own sphere. The 3 mm hip's left head is
# found beside its screws, the metal named. The abdomen series holds no
# joint head: exit code 1. (The thorax's heads through the whole run:
# ct_real_thorax.sh.)
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
# The 3 mm hip's left femur carries screws: the head is found, the metal named.
set +e
"$B/articula" run -i "$D/ct/hip-3mm-nifti/example_ct.nii.gz" -o "$T/hip-left" --joint hip --side left -q 2> "$T/hip-left.err"
set -e
python3 - "$T/hip-left/results.json" <<'PY'
import json, sys
results = json.load(open(sys.argv[1]))
checks = {c["name"]: c for c in results["qc"]["checks"]}
print(f"hip left: qc {results['qc']['status']}, metal near the head {checks['metal_near_head_mm3']['value']:.0f} mm^3")
assert checks["metal_near_head_mm3"]["status"] == "warn", checks["metal_near_head_mm3"]
assert 18 <= results["models"][0]["parameters"]["a_mm"] <= 30, results["models"][0]["parameters"]
assert results["models"][0]["parameters"]["t1_mm"] > 0, "the left side is +x in LPS"
PY
if [[ -d "$D/ct/breast-rt-shoulders-j2k-dicom" ]]; then
  # Lossy JPEG 2000 and osteoporotic: the label may be a thin shell (warned).
  run breast "$D/ct/breast-rt-shoulders-j2k-dicom" shoulder left yes
fi
if [[ -d "$D/ct/abdomen-j2k-dicom" ]]; then
  expect_rc 1 "$B/articula-segment" -i "$D/ct/abdomen-j2k-dicom" -o "$T/abdomen.nii.gz"
  grep -q "no femoral head found" "$tmp/err" || fail "abdomen: $(cat "$tmp/err")"
  [[ ! -e "$T/abdomen.nii.gz" ]] || fail "abdomen: a label was written"
  # One slice whose JPEG 2000 codestream lost its second half, in a file
  # that is whole (its fragment's length says so): OpenJPEG decoded what was
  # left without a word. Refused by name.
  cp -r "$D/ct/abdomen-j2k-dicom" "$T/j2k-cut"
  slice=$(ls "$T/j2k-cut" | sed -n 10p)
  python3 - "$T/j2k-cut/$slice" <<'PY'
import struct, sys
path = sys.argv[1]
b = open(path, "rb").read()
at = b.rindex(b"\xe0\x7f\x10\x00OB\x00\x00\xff\xff\xff\xff") + 12
items, pos = [], at
while True:
    tag, length = struct.unpack_from("<II", b, pos)
    if tag == 0xE0DDFFFE:
        break
    items.append(b[pos + 8:pos + 8 + length])
    pos += 8 + length
stream = b"".join(items[1:])
cut = stream[: len(stream) // 2 // 2 * 2]
out = b[:at] + struct.pack("<HHI", 0xFFFE, 0xE000, len(items[0])) + items[0]
out += struct.pack("<HHI", 0xFFFE, 0xE000, len(cut)) + cut + struct.pack("<HHI", 0xFFFE, 0xE0DD, 0)
open(path, "wb").write(out)
PY
  expect_rc 3 "$B/articula-segment" -i "$T/j2k-cut" -o "$T/j2k-cut.nii.gz"
  grep -q "^  $slice: its JPEG 2000 codestream is cut short" "$tmp/err" || fail "cut JPEG 2000: $(cat "$tmp/err")"
fi
echo "real CTs: ok"
