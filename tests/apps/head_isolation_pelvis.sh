#!/usr/bin/env bash
# The head search behind narrow joint gaps and under a socket's roof at
# thick slices, checked against the phantom's true heads: both hips in one
# CT behind 1.5 mm gaps with small heads, and a label at 1 x 1 x 3 mm that
# must stop within a slice of the femur's top.
# labels: full-size
source "$(dirname "$0")/common.bash"
source "$(dirname "$0")/head_truth.bash"

# Both hips, 1.5 mm gaps, small heads (17-19 mm), 0.8 x 0.8 x 1 mm voxels.
"$bin/articula" phantom -o "$tmp/pelvis" --both-hips --seed 4 --radius-range 17,19 --gap 1.5 --spacing 0.8,0.8,1 \
  --exact --no-dicom -q
for side in right left; do
  "$bin/articula" run -i "$tmp/pelvis/phantom.nii.gz" -o "$tmp/pelvis-$side" --side "$side" -q
  check "$tmp/pelvis-$side" "$tmp/pelvis/truth.json" "$side" 0.6 0.6
done

# At 3 mm slices the rays near the slice axis miss the dome's edge: the cut
# beyond the head's edges still reaches its pole, so that no column of the
# socket's roof stays in the label (it stops within a slice of the femur's top).
"$bin/articula" phantom -o "$tmp/roof" --seed 303 --exact --model superellipsoid --radius 25 --spacing 1,1,3 --gap 3 \
  --no-dicom -q
"$bin/articula" segment -i "$tmp/roof/phantom.nii.gz" -o "$tmp/roof-label.nii.gz" -q
python3 - "$tmp/roof-label.nii.gz" "$tmp/roof/femur_truth.nii.gz" <<'PY'
import gzip, struct, sys
def top_slice(path, value):
    """The highest k holding `value` (any non-zero value for None) in a NIfTI-1 image."""
    b = gzip.open(path).read()
    nx, ny, nz = struct.unpack_from("<3h", b, 42)
    datatype, = struct.unpack_from("<h", b, 70)
    offset = int(struct.unpack_from("<f", b, 108)[0])
    code = {2: "B", 4: "h", 512: "H", 8: "i", 768: "I"}[datatype]
    voxels = struct.unpack_from(f"<{nx * ny * nz}{code}", b, offset)
    plane = nx * ny
    return max(k for k in range(nz) if any((v == value if value else v) for v in voxels[k * plane:(k + 1) * plane]))
label, femur = top_slice(sys.argv[1], None), top_slice(sys.argv[2], 1)
assert label <= femur + 1, f"the label runs to slice {label}, the femur's top is slice {femur}: the socket's roof kept"
PY
echo "head isolation, pelvis: ok"
