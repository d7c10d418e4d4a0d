#!/usr/bin/env bash
# articula run on a phantom of a third, independent generator
# (bench/third_phantom.py) that used to come out silently wrong: both hips
# with the field of view shifted 60 mm to the left and the body cut at its
# edges (no air), 1.5 mm slices. The right head is out of view, and a
# rounded corner of the sacrum was reported as the right femoral head (a
# warning only); it must be refused, and the left head, 30 mm from the
# field's middle, found (it was refused as too near the midline). Its
# voxels are point-sampled (sub=1, half the generator's time): the test is
# of the search, not of partial volume.
# labels: full-size
source "$(dirname "$0")/common.bash"
source "$(dirname "$0")/third_phantom.bash"

python3 "$gen" out="$tmp/shifted" joint=hip both=1 side=left seed=410 R=24 gap=2.5 air=0 fov=135,70,65 fov_shift=60,0,0 \
  spacing=0.8,0.8,1.5 sub=1 > /dev/null
run shifted right
[ "$rc" -eq 1 ] || fail "the right hip, out of view, was not refused (exit $rc): $(score "$tmp/shifted-right" "$tmp/shifted.json" right)"
grep -q "no femoral head" "$tmp/shifted-right.err" || fail "refused without naming the reason: $(cat "$tmp/shifted-right.err")"
run shifted left
[ "$rc" -eq 0 ] || fail "the left head was not found (exit $rc): $(cat "$tmp/shifted-left.err")"
score "$tmp/shifted-left" "$tmp/shifted.json" left || fail "the left head came out wrong"
echo "head isolation on the third generator, the shifted field of view: ok"
