#!/usr/bin/env bash
# Heads outside the plausible radii (--min-radius 15, --max-radius 35 by
# default): a head of 37 mm or one of 12.7 mm is passed over for lesser bone
# (a trochanter), and the segmentation names the sphere it passed over, its
# radius and centre, and the options that take it in. With the range widened
# the head is found, and the report's radius check holds it to that range,
# not to the defaults.
# Labelled full-size, so the release tier alone runs it; the search's code
# runs under the sanitizers in the other head-search tests.
# labels: full-size
source "$(dirname "$0")/common.bash"

# phantom NAME RADIUS: a right hip at 1.2 x 1.2 x 1.5 mm with a head of that mean radius.
phantom() {
  "$bin/articula" phantom -o "$tmp/$1" --seed 77 --radius "$2" --spacing 1.2,1.2,1.5 --no-dicom -q
}
# passed_over NAME: checks the label's sidecar names the true head as passed over.
passed_over() {
  python3 - "$tmp/$1/truth.json" "$tmp/$1-label.nii.gz.json" <<'PY'
import json, math, re, sys
truth = json.load(open(sys.argv[1]))
warnings = json.load(open(sys.argv[2]))["warnings"]
named = [w for w in warnings if "outside the plausible head radii 15-35 mm" in w]
assert named, f"no warning names the head passed over: {warnings}"
m = re.search(r"radius ([0-9.]+) mm at \(([-0-9.e]+), ([-0-9.e]+), ([-0-9.e]+)\) mm", named[0])
assert m, named[0]
radius, centre = float(m.group(1)), [float(m.group(i)) for i in (2, 3, 4)]
off = math.dist(centre, truth["head_center_mm"])
print(f"passed over: radius {radius} mm (true radii {[round(r, 1) for r in truth['radii_mm']]}), {off:.2f} mm from the true centre")
assert off < 1.5, f"the sphere named lies {off:.2f} mm from the true head"
assert min(truth["radii_mm"]) - 1 < radius < max(truth["radii_mm"]) + 1, radius
assert "--min-radius/--max-radius" in named[0], named[0]
PY
}

phantom large 35
"$bin/articula" segment -i "$tmp/large/phantom.nii.gz" -o "$tmp/large-label.nii.gz" --side right -q
passed_over large
phantom small 12
"$bin/articula" segment -i "$tmp/small/phantom.nii.gz" -o "$tmp/small-label.nii.gz" --side right -q
passed_over small

# The large head with the range widened: found, and held to the user's range.
"$bin/articula" run -i "$tmp/large/phantom.nii.gz" -o "$tmp/run" --side right --max-radius 40 -q
python3 - "$tmp/large/truth.json" "$tmp/run/results.json" <<'PY'
import json, math, sys
truth, results = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
radius = next(c for c in results["qc"]["checks"] if c["name"] == "head_radius_mm")
print(f"head_radius_mm: {radius['value']:.2f} mm, {radius['status']} ({radius['rule']}); qc {results['qc']['status']}")
assert radius["status"] == "pass" and "40" in radius["rule"], radius
assert results["qc"]["status"] != "fail", results["qc"]["reasons"]
off = math.dist(results["head_center_mm"], truth["head_center_mm"])
assert off < 0.5, f"the head's centre {off:.2f} mm from the truth"
PY
echo "head size: ok"
