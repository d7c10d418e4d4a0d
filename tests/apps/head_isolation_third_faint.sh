#!/usr/bin/env bash
# articula run on a phantom of a third, independent generator
# (bench/third_phantom.py) that used to come out silently wrong: a thin,
# faint cortex (0.6 mm at 500 HU over 100 HU textured cancellous bone). The
# bone window cut the label 3 mm inside the dome, and the head was reported
# with its checks passing; it must be refused or found on its true surface.
# labels: full-size
source "$(dirname "$0")/common.bash"
source "$(dirname "$0")/third_phantom.bash"

python3 "$gen" out="$tmp/faint" joint=hip side=left seed=109 R=21 gap=2 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 \
  spacing=0.8,0.8,1.25 noise=20 > /dev/null
run faint left
if [ "$rc" -eq 0 ]; then
  score "$tmp/faint-left" "$tmp/faint.json" left || fail "the faint head came out wrong with exit 0"
else
  [ "$rc" -eq 1 ] || fail "the faint head: exit $rc"
  grep -q "qc\|no femoral head" "$tmp/faint-left.err" || fail "refused without a reason: $(cat "$tmp/faint-left.err")"
fi
echo "head isolation on the third generator, the faint cortex: ok"
