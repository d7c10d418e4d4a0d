#!/usr/bin/env bash
# Every bad input of the CT chain exits with the documented code and a clear message.
set -uo pipefail
python3() { /usr/bin/python3 "$@"; }  # Debian's, as common.bash binds it
B=$ARTICULA_BIN
T=$ARTICULA_TMP
rm -rf "$T" && mkdir -p "$T"
fail=0
expect() {  # expect CODE PATTERN -- command...
  local code=$1 pattern=$2
  shift 3
  "$@" > "$T/out" 2> "$T/err"
  local got=$?
  if [[ $got != "$code" ]] || ! grep -qi -- "$pattern" "$T/err"; then
    echo "FAIL: $* -> exit $got (expected $code), stderr:"; cat "$T/err"; fail=1
  fi
}
mkdir -p "$T/empty" "$T/notdicom"
echo "hello" > "$T/notdicom/readme.txt"
expect 3 "empty folder" -- "$B/articula-segment" -i "$T/empty" -o "$T/l.nii.gz"
expect 3 "no readable DICOM" -- "$B/articula-segment" -i "$T/notdicom" -o "$T/l.nii.gz"
expect 3 "not found" -- "$B/articula-segment" -i "$T/missing.nii.gz" -o "$T/l.nii.gz"
test ! -e "$T/l.nii.gz" || { echo "FAIL: a label was written for bad input"; fail=1; }

"$B/articula" phantom -o "$T/p" --seed 2 --spacing 1.5,1.5,2 -q
# The folder above a series: found none there, and the series' folder named.
mkdir -p "$T/above/study"
cp -r "$T/p/dicom" "$T/above/study/series"
expect 3 "found none .*DICOM files lie in $T/above/study/series (64 or more files): give that folder" -- \
  "$B/articula-segment" -i "$T/above" -o "$T/l.nii.gz"
# A missing slice: non-uniform spacing, named.
cp -r "$T/p/dicom" "$T/gap"
rm "$T/gap/slice_0020.dcm"
expect 3 "non-uniform slice spacing" -- "$B/articula-segment" -i "$T/gap" -o "$T/l.nii.gz"
# One slice cut short: inside its meta header (GDCM aborted the process),
# inside its pixel data (read zero-filled, exit 0), or before its preamble
# (skipped by GDCM): each refused, naming the file.
for cut in 300 5000; do
  rm -rf "$T/cut" && cp -r "$T/p/dicom" "$T/cut"
  head -c $cut "$T/p/dicom/slice_0020.dcm" > "$T/cut/slice_0020.dcm"
  expect 3 "^  slice_0020.dcm: element (0002\|^  slice_0020.dcm: element (7FE0,0010)" -- "$B/articula-segment" -i "$T/cut" -o "$T/l.nii.gz"
done
head -c 100 "$T/p/dicom/slice_0020.dcm" > "$T/cut/slice_0020.dcm"
expect 3 "missing slice?); the folder holds 1 file(s) that could not be read as DICOM: slice_0020.dcm" -- \
  "$B/articula-segment" -i "$T/cut" -o "$T/l.nii.gz"
test ! -e "$T/l.nii.gz" || { echo "FAIL: a label was written for a damaged series"; fail=1; }
# Slices that disagree with the series, each refused before ITK assembles
# the volume (which takes the first slice's size, spacing and orientation for
# all and ignores each slice's in-plane position), the file named.
edit="python3 $(dirname "$0")/dicom_edit.py"
slices() { rm -rf "$T/s" && cp -r "$T/p/dicom" "$T/s"; }
slices
# A block of slices shifted 20.3 mm in x.
$edit $(for i in $(seq 20 40); do echo "$T/s/slice_00$i.dcm $T/s/slice_00$i.dcm"; done) -- 0020,0032=shift:20.3,0,0
expect 3 "slice_0020.dcm (slice 21 of 64) lies 20.3 mm beside the line from the first slice to the last" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
slices && $edit "$T/p/dicom/slice_0030.dcm" "$T/s/slice_0030.dcm" 7FE0,0010=cut:7000
expect 3 "slice_0030.dcm (slice 31 of 64) holds 7000 bytes of pixel data, its header announces 75 x 95 pixels of 16 bits (14250 bytes)" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
slices && $edit "$T/p/dicom/slice_0030.dcm" "$T/s/slice_0030.dcm" 0028,0010=us:30000 0028,0011=us:30000
expect 3 "slice_0030.dcm (slice 31 of 64) is 30000 x 30000 pixels (rows x columns), the first slice 75 x 95" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
slices && $edit $(for f in "$T/p/dicom/"*.dcm; do echo "$f $T/s/$(basename "$f")"; done) -- 0028,0010=us:30000 0028,0011=us:30000
expect 3 "holds 14250 bytes of pixel data, its header announces 30000 x 30000 pixels" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
slices && $edit $(for i in $(seq 32 63); do echo "$T/p/dicom/slice_00$i.dcm $T/s/slice_00$i.dcm"; done) -- '0028,0030=1.4\1.4'
expect 3 "slice_0032.dcm (slice 33 of 64) has Pixel Spacing (1.4, 1.4) mm, the first slice (1.5, 1.5)" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
slices && $edit "$T/p/dicom/slice_0030.dcm" "$T/s/slice_0030.dcm" 0028,1053=0
expect 3 "slice_0030.dcm (slice 31 of 64) has Rescale Slope (0028,1053) 0; expected a non-zero number" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
slices && $edit "$T/p/dicom/slice_0030.dcm" "$T/s/slice_0030.dcm" '0020,0037=1\0\0\0\0.99\0.1'
expect 3 "slice_0030.dcm (slice 31 of 64) has Image Orientation Patient (1, 0, 0, 0, 0.99, 0.1), the first slice (1, 0, 0, 0, 1, 0)" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
slices && cp "$T/p/dicom/slice_0030.dcm" "$T/s/slice_0030b.dcm"
expect 3 "slice_0030.dcm (slice 31 of 65) and slice_0030b.dcm (slice 32 of 65) lie at one position along the slice normal (a duplicated slice?)" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
grep -q "gdcm\|Error: In" "$T/err" && { echo "FAIL: GDCM's raw lines reach the user:"; cat "$T/err"; fail=1; }
# A Recognition Code that is not ACR-NEMA's (GDCM asserted on it and aborted).
slices && $edit "$T/p/dicom/slice_0030.dcm" "$T/s/slice_0030.dcm" 0008,0010=1.2.840.10008.5.1.4.1.1.2
expect 3 "^  slice_0030.dcm: element (0008,0010) (Recognition Code, of ACR-NEMA files) at byte [0-9]* holds '1.2.840.10008.5.1.4.1.1.2'; expected a code beginning with ACR-NEMA" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
slices && $edit "$T/p/dicom/slice_0030.dcm" "$T/s/slice_0030.dcm" 7FE0,0010=drop  # GDCM skips it
expect 3 "missing slice?); the folder holds 1 file(s) that could not be read as DICOM: slice_0030.dcm" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
rm -rf "$T/s" && mkdir "$T/s" && cp "$T/p/dicom/slice_003"[012].dcm "$T/s/"
expect 3 "expected a 3-D volume of at least 4 voxels along each axis in $T/s, found size 95x75x3" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
# A series of bare data sets (no preamble and meta header): left out, with what to do.
rm -rf "$T/s" && mkdir "$T/s" && python3 - "$T/p/dicom" "$T/s" <<'PY'
import glob, os, sys
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.dcm"))):
    b = open(f, "rb").read()
    at = 132
    while int.from_bytes(b[at:at + 2], "little") == 0x0002:  # the meta header, explicit VR: (gggg,eeee) VR length
        vr = b[at + 4:at + 6]
        at += (12 + int.from_bytes(b[at + 8:at + 12], "little")) if vr in (b"OB", b"UN") else (8 + int.from_bytes(b[at + 6:at + 8], "little"))
    open(os.path.join(sys.argv[2], os.path.basename(f)), "wb").write(b[at:])
PY
expect 3 "found 64 bare DICOM data set(s) without the preamble and meta header .* rewrite them as DICOM files" -- \
  "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
# A bare data set (no preamble) that GDCM would take for DICOM and abort on: refused by name.
slices && printf '\x02\x00\x00\x00\x72\x00\x00\x00\x02\x00' > "$T/s/bare.dcm"
expect 3 "bare.dcm: no DICOM preamble, and " -- "$B/articula-segment" -i "$T/s" -o "$T/l.nii.gz"
test ! -e "$T/l.nii.gz" || { echo "FAIL: a label was written for slices that disagree"; fail=1; }
# Two CT series in one folder: listed, --series-uid needed.
"$B/articula" phantom -o "$T/q" --seed 3 --spacing 1.5,1.5,2 -q
mkdir -p "$T/two" && cp "$T/p/dicom/"*.dcm "$T/two/" && for f in "$T/q/dicom/"*.dcm; do cp "$f" "$T/two/q_$(basename "$f")"; done
expect 3 "several CT series" -- "$B/articula-segment" -i "$T/two" -o "$T/l.nii.gz"
# A series whose Series Instance UID is empty: listed as 'empty' and chosen by that name.
mkdir -p "$T/blank" && cp "$T/p/dicom/"*.dcm "$T/blank/"
python3 - "$T/q/dicom" "$T/blank" <<'PY'
import glob, os, struct, sys
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.dcm"))):
    b = bytearray(open(f, "rb").read())
    i = b.find(b"\x20\x00\x0e\x00", 132)  # (0020,000E), implicit VR: a 4-byte length follows
    n = struct.unpack_from("<I", b, i + 4)[0]
    b[i + 8:i + 8 + n] = bytes(n)
    open(os.path.join(sys.argv[2], "q_" + os.path.basename(f)), "wb").write(b)
PY
expect 3 "  empty  modality CT, 64 files, 'articula phantom seed 3'" -- "$B/articula-segment" -i "$T/blank" -o "$T/l.nii.gz"
"$B/articula-segment" -i "$T/blank" -o "$T/blank.nii.gz" --series-uid empty --json -q > "$T/blank.json" ||
  { echo "FAIL: --series-uid empty"; fail=1; }
grep -q '"series_used": "empty"' "$T/blank.json" || { echo "FAIL: series_used: $(cat "$T/blank.json")"; fail=1; }
# An HU window with no voxel.
expect 3 "no voxel in the HU window" -- "$B/articula-segment" -i "$T/p/phantom.nii.gz" -o "$T/l.nii.gz" --hu-min 5000 --hu-max 6000
# No head on the left of a right hip phantom (with a radius range that excludes the trochanter).
expect 1 "no femoral head found" -- "$B/articula-segment" -i "$T/p/phantom.nii.gz" -o "$T/l.nii.gz" --side left --min-radius 30
# An empty label.
"$B/articula-segment" -i "$T/p/phantom.nii.gz" -o "$T/head.nii.gz" -q
python3 - "$T/empty.nii.gz" <<'PY'
import gzip, struct, sys
# A minimal NIfTI-1 label: 4x4x4 uint8 zeros, 1 mm voxels.
h = bytearray(348)
struct.pack_into("<i", h, 0, 348)
struct.pack_into("<8h", h, 40, 3, 4, 4, 4, 1, 1, 1, 1)
struct.pack_into("<hh", h, 70, 2, 8)
struct.pack_into("<8f", h, 76, 1, 1, 1, 1, 0, 0, 0, 0)
struct.pack_into("<f", h, 108, 352.0)
struct.pack_into("<f", h, 112, 1.0)
struct.pack_into("<h", h, 252, 1)  # qform_code: scanner, identity
h[344:348] = b"n+1\0"
gzip.open(sys.argv[1], "wb").write(bytes(h) + b"\0" * 4 + b"\0" * 64)
PY
expect 3 "no voxel set" -- "$B/articula-mesh" -i "$T/empty.nii.gz" -o "$T/m.stl"
expect 2 "smooth-iterations" -- "$B/articula-mesh" -i "$T/head.nii.gz" -o "$T/m.vtp" --smooth-iterations -1
# A mesh with no triangles, a too small selection, a bad --select.
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n' > "$T/points-only.ply"
expect 3 "no triangles" -- "$B/articula-sample" -i "$T/points-only.ply" -o "$T/s.ply"
"$B/articula-mesh" -i "$T/head.nii.gz" -o "$T/head.vtp" -q
expect 3 "expected at least" -- "$B/articula-sample" -i "$T/head.vtp" -o "$T/s.ply" --select sphere:0,0,0,1
expect 2 "expected auto" -- "$B/articula-sample" -i "$T/head.vtp" -o "$T/s.ply" --select blob
# MetaImage CTs that ITK reads without a word: cut short (raw or
# compressed), a NaN voxel, one value everywhere. A whole one reads.
python3 - "$T" <<'PY'
import math, struct, sys, zlib
n, folder = 24, sys.argv[1]
def header(kind, extra=""):
    return (f"ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n{extra}"
            f"DimSize = {n} {n} {n}\nElementSpacing = 1.5 1.5 1.5\nElementType = {kind}\nElementDataFile = LOCAL\n").encode()
ball = [1000 if math.dist((i, j, k), (12, 12, 12)) < 8 else 0 for k in range(n) for j in range(n) for i in range(n)]
raw = struct.pack(f"<{n ** 3}h", *ball)
open(f"{folder}/whole.mha", "wb").write(header("MET_SHORT") + raw)
open(f"{folder}/cut.mha", "wb").write(header("MET_SHORT") + raw[: len(raw) // 2])
packed = zlib.compress(raw)
open(f"{folder}/cut-zlib.mha", "wb").write(
    header("MET_SHORT", f"CompressedData = True\nCompressedDataSize = {len(packed)}\n") + packed[: len(packed) // 2])
values = [float(v) for v in ball]
values[n ** 3 // 2] = float("nan")
open(f"{folder}/nan.mha", "wb").write(header("MET_FLOAT") + struct.pack(f"<{n ** 3}f", *values))
open(f"{folder}/flat.mha", "wb").write(header("MET_SHORT") + struct.pack(f"<{n ** 3}h", *([-1000] * n ** 3)))
# ITK's MetaIO keeps zeros without CompressedDataSize, and spun for ever on a negative NDims given twice.
open(f"{folder}/unsized-zlib.mha", "wb").write(header("MET_SHORT", "CompressedData = True\n") + packed)
open(f"{folder}/ndims.mha", "wb").write(header("MET_SHORT").replace(b"NDims = 3", b"NDims = 2"))
open(f"{folder}/twice.mha", "wb").write(header("MET_SHORT", "NDims = -10 20 30\n") + raw)
open(f"{folder}/no-equals.mha", "wb").write(header("MET_SHORT").replace(b"NDims = 3", b"NDims") + raw)
PY
expect 3 "CompressedData = True without CompressedDataSize: .*expected the line CompressedDataSize = $(( $(stat -c %s "$T/unsized-zlib.mha") - $(grep -abo 'LOCAL' "$T/unsized-zlib.mha" | cut -d: -f1) - 6 ))" -- \
  "$B/articula-segment" -i "$T/unsized-zlib.mha" -o "$T/l.nii.gz"
expect 3 "NDims = 2; expected NDims = 3" -- "$B/articula-segment" -i "$T/ndims.mha" -o "$T/l.nii.gz"
expect 3 "gives 'NDims' twice" -- timeout 60 "$B/articula-segment" -i "$T/twice.mha" -o "$T/l.nii.gz"
expect 3 "line 'NDims' has no '='" -- timeout 60 "$B/articula-segment" -i "$T/no-equals.mha" -o "$T/l.nii.gz"
expect 3 "announces 27648 bytes of voxel data, the file holds 13824: the file is cut short" -- \
  "$B/articula-segment" -i "$T/cut.mha" -o "$T/l.nii.gz"
expect 3 "compressed voxel data is damaged\|the file is cut short" -- "$B/articula-segment" -i "$T/cut-zlib.mha" -o "$T/l.nii.gz"
expect 3 "1 of 13824 voxels are not finite numbers" -- "$B/articula-segment" -i "$T/nan.mha" -o "$T/l.nii.gz"
expect 3 "every voxel holds the same value" -- "$B/articula-segment" -i "$T/flat.mha" -o "$T/l.nii.gz"
# An NRRD whose size has more digits than any volume (ITK wraps it and
# allocates what the wrapped size asks for) is refused by name.
printf 'NRRD0004\ntype: short\ndimension: 3\nsizes: 3333333333333333333333334 4 4\nencoding: raw\n\n' > "$T/huge.nrrd"
expect 3 "sizes: '3333333333333333333333334 4 4'; expected whole numbers of at most 18 digits" -- \
  "$B/articula-segment" -i "$T/huge.nrrd" -o "$T/l.nii.gz"
test ! -e "$T/l.nii.gz" || { echo "FAIL: a label was written for a damaged MetaImage"; fail=1; }
# The whole file passes the reader's checks (its ball is too small for a head: exit 1).
expect 1 "no femoral head found" -- "$B/articula-segment" -i "$T/whole.mha" -o "$T/l.nii.gz"
exit $fail
