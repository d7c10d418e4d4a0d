#!/usr/bin/env bash
# Hostile and careless input: each case exits with its documented code, says
# what was wrong, and leaves nothing behind that looks complete.
source "$(dirname "$0")/common.bash"
A="$bin/articula"

# cap_points FILE N SEED: N points of a 22 mm sphere cap (CSV).
cap_points() {
  python3 - "$@" <<'PY'
import math, random, sys
random.seed(int(sys.argv[3]))
with open(sys.argv[1], "w") as f:
    f.write("x,y,z\n")
    for _ in range(int(sys.argv[2])):
        t, p = random.uniform(0, 1.2), random.uniform(0, 2 * math.pi)
        f.write(f"{22 * math.sin(t) * math.cos(p)},{22 * math.sin(t) * math.sin(p)},{22 * math.cos(t)}\n")
PY
}
cap_points "$tmp/head.csv" 300 1
cp "$tmp/head.csv" "$tmp/head.orig"

# An output that is an input: fit's table beside head.json would be head.csv, the input.
expect_rc 2 "$A" fit -i "$tmp/head.csv" -o "$tmp/head.json" --force
grep -q "would overwrite the input" "$tmp/err" || fail "fit over its input: $(cat "$tmp/err")"
cmp -s "$tmp/head.csv" "$tmp/head.orig" || fail "fit overwrote its input points"
[ ! -e "$tmp/head.json" ] || fail "fit wrote head.json before refusing"
expect_rc 2 "$A" sample -i "$tmp/head.csv" -o "$tmp/head.csv" --force
cmp -s "$tmp/head.csv" "$tmp/head.orig" || fail "sample overwrote its input"

# A file whose first line drives a terminal (clear the screen, set the
# window title): the message quotes it with the control bytes escaped.
printf '\033[2J\033]0;owned\007hello\n' > "$tmp/esc.ply"
expect_rc 3 "$A" fit -i "$tmp/esc.ply" -o "$tmp/esc.json"
if LC_ALL=C grep -q $'[\x01-\x08\x0b-\x1f\x7f]' "$tmp/err"; then fail "control bytes reached the terminal: $(cat -v "$tmp/err")"; fi
grep -qF '\x1b[2J\x1b]0;owned\x07hello' "$tmp/err" || fail "the line is not quoted escaped: $(cat -v "$tmp/err")"

# A fits.json whose models are 10^5 nested arrays: a message, not a stack overflow.
python3 -c "import sys; sys.stdout.write('{\"models\": ' + '[' * 100000 + ']' * 100000 + '}')" > "$tmp/deep.json"
expect_rc 3 "$A" errors -i "$tmp/head.csv" --fits "$tmp/deep.json" -o "$tmp/deep"
grep -q "expected an object, found an array" "$tmp/err" || fail "nested JSON: $(head -c 300 "$tmp/err")"

# A 10^6-character model name with terminal escapes: a short, escaped excerpt.
python3 -c "import sys; sys.stdout.write('{\"models\": [{\"model\": \"\\\\u001b[31m' + 'x' * 1000000 + '\"}]}')" > "$tmp/big.json"
expect_rc 3 "$A" errors -i "$tmp/head.csv" --fits "$tmp/big.json" -o "$tmp/big"
[ "$(wc -c < "$tmp/err")" -lt 400 ] || fail "the message echoes $(wc -c < "$tmp/err") bytes of input"
grep -q 'unknown shape model' "$tmp/err" || fail "big name: $(head -c 300 "$tmp/err")"
if grep -q $'\x1b' "$tmp/err"; then fail "an escape sequence reached stderr raw"; fi
grep -q '\\x1b' "$tmp/err" || fail "the escape is not shown escaped"

# Fields a model does not have, and sizes beyond any body in millimetres: refused, not ignored.
shape() {  # shape MODEL RADII EXPONENTS: a fits.json of one model
  echo "{\"models\":[{\"model\":\"$1\",\"center_mm\":[0,0,0],\"radii_mm\":$2,\"rotation_deg\":[0,0,0],\"exponents\":$3,\"cx\":[1,0,0,0],\"cy\":[1,0,0,0]}]}"
}
shape ellipsoid "[22,22,21]" "[1.5,1.5,1.5]" > "$tmp/ellipsoid-exponents.json"
expect_rc 3 "$A" errors -i "$tmp/head.csv" --fits "$tmp/ellipsoid-exponents.json" -o "$tmp/ee"
grep -q "exponents \[1.5,1.5,1.5\] given for the model 'ellipsoid'" "$tmp/err" || fail "ellipsoid exponents: $(cat "$tmp/err")"
shape ellipsoid "[1e300,1e300,1e300]" "[2,2,2]" > "$tmp/huge.json"
expect_rc 3 "$A" errors -i "$tmp/head.csv" --fits "$tmp/huge.json" -o "$tmp/huge"
grep -q "within 1e5 mm" "$tmp/err" || fail "radii 1e300: $(cat "$tmp/err")"
[ ! -e "$tmp/huge/summary.json" ] || fail "errors wrote a summary for radii of 1e300"

# errors -o over a folder holding one of its outputs from another run: refused before any file is written.
"$A" fit -i "$tmp/head.csv" -o "$tmp/fits.json" -q
mkdir -p "$tmp/mixed" && echo old > "$tmp/mixed/points_superovoid.ply"
expect_rc 2 "$A" errors -i "$tmp/head.csv" --fits "$tmp/fits.json" -o "$tmp/mixed"
grep -q "points_superovoid.ply' exists" "$tmp/err" || fail "mixed outputs: $(cat "$tmp/err")"
[ "$(ls "$tmp/mixed")" = "points_superovoid.ply" ] || fail "errors wrote beside an old output: $(ls "$tmp/mixed")"
# errors killed midway (SIGKILL once its incomplete-marker appears): the
# folder does not look finished (no summary.json), and the next run without
# --force finishes it.
cap_points "$tmp/many.csv" 300000 2
"$A" errors -i "$tmp/many.csv" --fits "$tmp/fits.json" -o "$tmp/killed" -q &
pid=$!
for _ in $(seq 1 3000); do [ -e "$tmp/killed/.errors-incomplete" ] && break; sleep 0.01; done
kill -KILL "$pid"; wait "$pid" 2>/dev/null || true
[ -e "$tmp/killed/.errors-incomplete" ] || fail "errors finished before it could be killed, or left no marker"
[ ! -e "$tmp/killed/summary.json" ] || fail "a killed errors run left summary.json: the folder looks finished"
"$A" errors -i "$tmp/many.csv" --fits "$tmp/fits.json" -o "$tmp/killed" -q || fail "the rerun after a kill did not finish"
[ -e "$tmp/killed/summary.json" ] && [ ! -e "$tmp/killed/.errors-incomplete" ] || fail "the rerun left the folder unfinished"
[ -z "$(find "$tmp/killed" -name '.tmp-*')" ] || fail "temporary files left behind"

# An output that cannot be written: exit 1 naming it and the system's reason, before any work.
mkdir -p "$tmp/dir.json"
expect_rc 1 "$A" fit -i "$tmp/head.csv" -o "$tmp/dir.json"
grep -q "it is a folder" "$tmp/err" || fail "-o a folder: $(cat "$tmp/err")"
touch "$tmp/notafolder"
expect_rc 1 "$A" fit -i "$tmp/head.csv" -o "$tmp/notafolder/fits.json"
grep -q "cannot create the folder" "$tmp/err" || fail "-o under a file: $(cat "$tmp/err")"

# Contact pairs far beyond the solver's range (a centre at 1e300, radii of
# 1e300, crossing needles of axes 1e-9 and 1e9): each row refused by line
# (a bad row is skipped and named; only bad rows: exit 3 and no output).
pairs="$tmp/far.csv"
{ head -1 "$ARTICULA_SOURCE/testdata/contact/pairs.csv"
  echo "1e300,0,0,1,0,0,0,2,2,2,2,2,2,,4,0,0,1,0,0,0,1,1,1,2,2,2,,,"
  echo "0,0,0,1,0,0,0,1e300,2,2,2,2,2,,4,0,0,1,0,0,0,1,1,1,2,2,2,,,"
  echo "0,0,0,1,0,0,0,1e9,1e-9,1e-9,2,2,2,,0,0,0,0.7071067811865476,0,0,0.7071067811865476,1e9,1e-9,1e-9,2,2,2,,,"
} > "$pairs"
expect_rc 3 "$A" contact --pairs "$pairs" -o "$tmp/far_out.csv"
for line in 2 3 4; do grep -q "far.csv:$line:" "$tmp/err" || fail "contact row $line not named: $(cat "$tmp/err")"; done
grep -q "1e-06 to 1e+06 mm\|1e-6 to 1e6 mm" "$tmp/err" || fail "contact: the range is not stated: $(cat "$tmp/err")"
[ ! -e "$tmp/far_out.csv" ] || fail "contact wrote an output of refused rows"
# NIfTI files ITK would read silently wrong: a 4-D image (ITK takes the
# first volume), a pixdim of 0 or NaN (ITK puts 1 mm in its place).
nifti() {  # nifti PATH DIMS PIXDIMS: an int16 NIfTI-1 file of 500 HU
  python3 - "$@" <<'PY'
import struct, sys
path, dims, pixdim = sys.argv[1], [int(x) for x in sys.argv[2].split(",")], [float(x) for x in sys.argv[3].split(",")]
hdr = bytearray(348)
struct.pack_into("<i", hdr, 0, 348)
struct.pack_into("<8h", hdr, 40, len(dims), *(dims + [1] * (7 - len(dims))))
struct.pack_into("<hh", hdr, 70, 4, 16)
struct.pack_into("<8f", hdr, 76, 1.0, *(pixdim + [1.0] * (7 - len(pixdim))))
struct.pack_into("<ff", hdr, 108, 352.0, 1.0)
struct.pack_into("<h", hdr, 252, 1)  # qform_code: scanner; quaternion and offsets 0 (identity)
hdr[344:348] = b"n+1\0"
n = 1
for d in dims: n *= d
open(path, "wb").write(bytes(hdr) + bytes(4) + struct.pack("<%dh" % n, *([500] * n)))
PY
}
nifti "$tmp/4d.nii" 8,8,8,2 1,1,1,1
expect_rc 3 "$A" segment -i "$tmp/4d.nii" -o "$tmp/4d-label.nii.gz"
grep -q "expected one 3-D volume, found 4-D" "$tmp/err" || fail "4-D: $(cat "$tmp/err")"
for bad in 0 nan; do
  nifti "$tmp/pixdim-$bad.nii" 8,8,8 1,$bad,1
  gzip -kf "$tmp/pixdim-$bad.nii"
  expect_rc 3 "$A" segment -i "$tmp/pixdim-$bad.nii.gz" -o "$tmp/pixdim-label.nii.gz"
  grep -q "pixdim\[2\]" "$tmp/err" || fail "pixdim $bad: $(cat "$tmp/err")"
  [ ! -e "$tmp/pixdim-label.nii.gz" ] || fail "a label was written for pixdim $bad"
done

# A NaN in the orientation (here srow_x[0]): ITK aborted the process; a
# value near the float range: ITK's SVD never ended.
for value in nan 1e30; do
  nifti "$tmp/bad-srow.nii" 8,8,8 1,1,1
  python3 - "$tmp/bad-srow.nii" "$value" <<'PY'
import struct, sys
b = bytearray(open(sys.argv[1], "rb").read())
struct.pack_into("<h", b, 254, 1)                  # sform_code: scanner
struct.pack_into("<f", b, 280, float(sys.argv[2])) # srow_x[0]
open(sys.argv[1], "wb").write(b)
PY
  expect_rc 3 timeout 60 "$A" segment -i "$tmp/bad-srow.nii" -o "$tmp/srow-label.nii.gz"
  grep -q "orientation (pixdim\[0\], quatern, qoffset, srow) holds .* at byte 280" "$tmp/err" || fail "srow $value: $(cat "$tmp/err")"
done

# Voxels with no place in the patient (no qform, no sform), or two places
# (an sform that mirrors the qform: a right hip read as a left one by some
# tools); a matching sform passes to the next check (one value everywhere).
place() {  # place PATH QFORM_CODE SFORM_CODE SROW_X0
  python3 - "$@" <<'PY'
import struct, sys
b = bytearray(open(sys.argv[1], "rb").read())
struct.pack_into("<hh", b, 252, int(sys.argv[2]), int(sys.argv[3]))
struct.pack_into("<12f", b, 280, float(sys.argv[4]), 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0)
open(sys.argv[1], "wb").write(b)
PY
}
nifti "$tmp/placed.nii" 8,8,8 1,1,1
place "$tmp/placed.nii" 0 0 1
expect_rc 3 "$A" segment -i "$tmp/placed.nii" -o "$tmp/placed-label.nii.gz"
grep -q "NIfTI header states no orientation (qform_code and sform_code are 0)" "$tmp/err" || fail "no orientation: $(cat "$tmp/err")"
place "$tmp/placed.nii" 1 1 -1
expect_rc 3 "$A" segment -i "$tmp/placed.nii" -o "$tmp/placed-label.nii.gz"
grep -q "qform and its sform put a corner of the volume 14 mm apart (one mirrors the other)" "$tmp/err" ||
  fail "sform mirroring qform: $(cat "$tmp/err")"
place "$tmp/placed.nii" 1 1 1
expect_rc 3 "$A" segment -i "$tmp/placed.nii" -o "$tmp/placed-label.nii.gz"
grep -q "every voxel holds the same value" "$tmp/err" || fail "matching sform: $(cat "$tmp/err")"
[ ! -e "$tmp/placed-label.nii.gz" ] || fail "a label was written for a NIfTI without a place"

# Ranges checked before any work; an unknown command is one, --help or not.
expect_rc 2 "$A" segment -i "$tmp/4d.nii" -o "$tmp/r.nii.gz" --max-radius 1e6
grep -q "max-radius (mm): expected 1 to 60" "$tmp/err" || fail "max-radius: $(cat "$tmp/err")"
expect_rc 2 "$A" segment -i "$tmp/4d.nii" -o "$tmp/r.nii.gz" --close-radius 1000
expect_rc 2 "$A" segment -i "$tmp/4d.nii" -o "$tmp/r.nii.gz" --surface-hu nan
grep -q "surface-hu (HU): expected -2000 to 40000, found nan" "$tmp/err" || fail "surface-hu: $(cat "$tmp/err")"
expect_rc 2 "$A" sample -i "$tmp/head.csv" -o "$tmp/s.ply" --max-radius 1e300
grep -q "expected 0 < min < max <= 200 mm" "$tmp/err" || fail "sample max-radius: $(cat "$tmp/err")"
expect_rc 2 "$A" sample -i "$tmp/head.csv" -o "$tmp/s.ply" --band 1e300
[ ! -e "$tmp/r.nii.gz" ] && [ ! -e "$tmp/s.ply" ] || fail "an output was written for an option out of range"
expect_rc 2 "$A" fit -i "$tmp/head.csv" -o "$tmp/t.json" --threads 100000
[ ! -e "$tmp/t.json" ] || fail "fit ran with 100000 threads asked"
expect_rc 2 "$A" fit -i "$tmp/head.csv" -o "$tmp/t.json" --sample-points 500
grep -q "sample_points: expected 0 (all) or >= 1000" "$tmp/err" || fail "sample-points: $(cat "$tmp/err")"
# A seed beyond its type's range: refused naming the range, not clamped.
expect_rc 2 "$A" fit -i "$tmp/head.csv" -o "$tmp/t.json" --seed 99999999999999999999
grep -q -- "--seed: expected a whole number in \[0, 9223372036854775807\], found '99999999999999999999'" "$tmp/err" ||
  fail "seed out of range: $(cat "$tmp/err")"
expect_rc 2 "$A" fit -i "$tmp/head.csv" -o "$tmp/t.json" --seed -1
[ ! -e "$tmp/t.json" ] || fail "fit ran with a seed out of range"
expect_rc 2 "$A" nosuch --help
grep -q "unknown command 'nosuch'" "$tmp/err" || fail "nosuch --help: $(cat "$tmp/err")"
# Manifest columns the batch sets itself, or that no stage has: refused by
# --validate and by the batch before any subject runs.
# refused_manifest NAME TEXT PATTERN [batch options...]: the batch exits 3
# naming the problem, and makes no study folder.
refused_manifest() {
  local name=$1 text=$2 pattern=$3; shift 3
  printf "$text" > "$tmp/$name.csv"
  expect_rc 3 "$A" batch "$tmp/$name.csv" -o "$tmp/study-$name" "$@"
  grep -q -- "$pattern" "$tmp/err" || fail "manifest $name: $(cat "$tmp/err")"
  [ ! -e "$tmp/study-$name" ] || fail "batch made a study folder for manifest $name"
}
refused_manifest until 'subject,input,joint,side,until\ns1,4d.nii,hip,left,sample\n' \
  "column 'until': --until is set by the batch"
refused_manifest output 'subject,input,joint,side,output\ns1,4d.nii,hip,left,elsewhere\n' "column 'output'" --validate
refused_manifest typo 'subject,input,joint,side,smoothnes\ns1,4d.nii,hip,left,0.5\n' \
  "typo.csv:2: subject s1: its options do not parse.*smoothnes" --validate
refused_manifest bom '\xef\xbb\xbfid,input,joint,side\ns1,4d.nii,hip,left\n' "found 'id,input,joint,side'" --validate
refused_manifest dots 'subject,input,joint,side\n..,4d.nii,hip,left\n' "not starting with '.'" --validate
# Tables saved as UTF-16 ("Unicode text"), with its byte-order mark or
# without (NUL bytes): refused at every CSV entry point, saying what to do;
# a UTF-8 byte-order mark (Excel's "CSV UTF-8") is read as it is (in a
# manifest: "bom" above).
utf16="the file is UTF-16 (or has NUL bytes); save it as UTF-8 CSV"
printf 'subject,input,joint,side\ns1,4d.nii,hip,left\n' | iconv -t UTF-16 > "$tmp/m16.csv"
printf 'subject,input,joint,side\ns1,4d.nii,hip,left\n' | iconv -t UTF-16BE > "$tmp/m16be.csv"
for m in m16 m16be; do
  for validate in --validate ""; do
    expect_rc 3 "$A" batch "$tmp/$m.csv" -o "$tmp/study-$m" $validate
    grep -q "$m.csv:1: $utf16" "$tmp/err" || fail "batch -m $m.csv: $(cat "$tmp/err")"
    [ ! -e "$tmp/study-$m" ] || fail "batch made a study folder for a UTF-16 manifest"
  done
done
iconv -t UTF-16 "$ARTICULA_SOURCE/testdata/contact/pairs.csv" > "$tmp/pairs16.csv"
expect_rc 3 "$A" contact --pairs "$tmp/pairs16.csv" -o "$tmp/pairs16_out.csv"
grep -q "pairs16.csv:1: $utf16" "$tmp/err" || fail "contact --pairs UTF-16: $(cat "$tmp/err")"
iconv -t UTF-16LE "$tmp/head.csv" > "$tmp/head16.csv"
expect_rc 3 "$A" fit -i "$tmp/head16.csv" -o "$tmp/fits16.json"
grep -q "head16.csv:1: $utf16" "$tmp/err" || fail "points UTF-16: $(cat "$tmp/err")"
{ printf '\xef\xbb\xbf'; cat "$tmp/head.csv"; } > "$tmp/head-bom.csv"
expect_rc 0 "$A" fit -i "$tmp/head-bom.csv" -o "$tmp/fits-bom.json" -q

# A NIfTI cut short (half its voxels), plain and re-gzipped: refused, not zero-filled.
nifti "$tmp/whole.nii" 16,16,16 1,1,1
head -c 4500 "$tmp/whole.nii" > "$tmp/half.nii"
gzip -kf "$tmp/half.nii"
for f in half.nii half.nii.gz; do
  expect_rc 3 "$A" segment -i "$tmp/$f" -o "$tmp/half-label.nii.gz"
  grep -q "truncated: expected 8544 bytes of header and voxels (4096 voxels of 16 bits), found 4500" "$tmp/err" ||
    fail "truncated $f: $(cat "$tmp/err")"
done
gzip -c "$tmp/whole.nii" > "$tmp/whole.nii.gz"
head -c $(( $(wc -c < "$tmp/whole.nii.gz") - 12 )) "$tmp/whole.nii.gz" > "$tmp/cut.nii.gz"  # no gzip trailer
expect_rc 3 "$A" segment -i "$tmp/cut.nii.gz" -o "$tmp/half-label.nii.gz"
grep -Eq "damaged|truncated|expected a NIfTI header" "$tmp/err" || fail "a cut gzip stream: $(cat "$tmp/err")"
[ ! -e "$tmp/half-label.nii.gz" ] || fail "a label was written for a truncated image"
echo "bad input: ok"
