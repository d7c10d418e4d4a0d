#!/usr/bin/env bash
# articula simulate: the shipped scenes run (the ball stays in its bowl and
# loses energy, the spinning ellipsoid meets its plane), the outputs are
# complete with summary.json last, and bad scenes are refused with the file
# and the field named, before any output is written.
source "$(dirname "$0")/common.bash"
src=${ARTICULA_SOURCE:?}

# The thesis's ball in a bowl, 2 s.
python3 - "$src/scenes/ball_in_bowl.json" "$tmp/bowl.json" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
scene["duration"] = 2.0
json.dump(scene, open(sys.argv[2], "w"))
PY
expect_rc 0 "$bin/articula" simulate -i "$tmp/bowl.json" -o "$tmp/bowl" --json -q
python3 - "$tmp/bowl" <<'PY'
import csv, json, math, sys
out = sys.argv[1]
summary = json.load(open(f"{out}/summary.json"))
assert summary["simulated_s"] == 2.0 and summary["output_rows"] == 201, summary
assert summary["steps"] > 100 and 0 < summary["min_step_s"] <= summary["mean_step_s"] <= summary["max_step_s"], summary
assert summary["contact_evaluations"] >= summary["steps"], summary
rows = list(csv.DictReader(open(f"{out}/trajectory.csv")))
assert len(rows) == 201, len(rows)
for r in rows:  # inside the bowl, at most the Hertz sag through its wall
    d = math.dist((float(r["ball_x_m"]), float(r["ball_y_m"]), float(r["ball_z_m"])), (0, 0, 1.0))
    assert d <= 0.9 + 1e-3, (r["time_s"], d)
    q = [float(r[f"ball_q{c}"]) for c in "wxyz"]
    assert abs(sum(v * v for v in q) - 1) < 1e-9, q
energy = [float(r["total_j"]) for r in rows]
assert energy[-1] < energy[0], (energy[0], energy[-1])
assert max(b - a for a, b in zip(energy, energy[1:])) < 1e-3 * energy[0], "energy rose"
steps = list(csv.DictReader(open(f"{out}/steps.csv")))
assert len(steps) == summary["steps"], (len(steps), summary["steps"])
contacts = list(csv.DictReader(open(f"{out}/contacts.csv")))
assert len(contacts) > 150 and all(float(c["normal_n"]) > 0 for c in contacts)
for figure in ("trajectory.svg", "contact_forces.svg", "steps.svg"):
    svg = open(f"{out}/{figure}").read()
    assert svg.startswith("<svg") and svg.rstrip().endswith("</svg>") and "<polyline" in svg, figure
    assert figure in summary["outputs"], summary["outputs"]
PY

# The spinning ellipsoid on a plane touches it.
expect_rc 0 "$bin/articula" simulate -i "$src/scenes/ellipsoid_spin.json" -o "$tmp/egg" -q
[ "$(wc -l < "$tmp/egg/contacts.csv")" -gt 50 ] || fail "the ellipsoid never touched its plane"

# Two free bodies in zero gravity: the pair's forces are equal and opposite.
expect_rc 0 "$bin/articula" simulate -i "$src/scenes/two_ellipsoids.json" -o "$tmp/two" -q
python3 - "$tmp/two/trajectory.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
def momentum(r):
    return [float(r[f"a_v{c}_m_s"]) + 3.0 * float(r[f"b_v{c}_m_s"]) for c in "xyz"]
start, end = momentum(rows[0]), momentum(rows[-1])
assert max(abs(a - b) for a, b in zip(start, end)) < 1e-8, (start, end)
assert float(rows[-1]["b_vx_m_s"]) > 0.1, "they never collided"
PY

# The three-segment foot, with surfaces and with points: it lands on its heel
# and rolls to the toes (the heel leaves the ground while the hallux bears).
for sole in surfaces points; do
  expect_rc 0 "$bin/articula" simulate -i "$src/scenes/foot_$sole.json" -o "$tmp/foot-$sole" -q
  python3 - "$tmp/foot-$sole/contacts.csv" "$sole" <<'PY'
import csv, sys
heel, hallux = ({0}, {5}) if sys.argv[2] == "surfaces" else (set(range(8)), set(range(26, 31)))
rows = list(csv.DictReader(open(sys.argv[1])))
times = sorted({float(r["time_s"]) for r in rows})
touching = {t: set() for t in times}
for r in rows:
    touching[float(r["time_s"])].add(int(r["contact"]))
first = lambda ids: min(t for t in times if touching[t] & ids)
assert first(heel) < first(hallux), (first(heel), first(hallux))
assert any(touching[t] & hallux and not touching[t] & heel for t in times), "the heel never left the ground"
PY
done

# A second run refuses to overwrite; --force redoes it.
expect_rc 2 "$bin/articula" simulate -i "$tmp/bowl.json" -o "$tmp/bowl"
grep -q "refusing to overwrite" "$tmp/err" || fail "overwrite message: $(cat "$tmp/err")"

# Bad scenes: exit 3, the file and the field named, nothing written.
bad() {  # bad NAME 'PYTHON EXPRESSION ON scene' 'EXPECTED MESSAGE'
  python3 - "$tmp/bowl.json" "$tmp/$1.json" "$2" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
exec(sys.argv[3])
json.dump(scene, open(sys.argv[2], "w"))
PY
  expect_rc 3 "$bin/articula" simulate -i "$tmp/$1.json" -o "$tmp/out-$1"
  grep -q -- "$3" "$tmp/err" || fail "$1: expected '$3', found: $(cat "$tmp/err")"
  grep -q "$1.json" "$tmp/err" || fail "$1: the file is not named: $(cat "$tmp/err")"
  [ ! -e "$tmp/out-$1/summary.json" ] && [ ! -e "$tmp/out-$1/trajectory.csv" ] || fail "$1: outputs written"
}
bad negative-mass 'scene["bodies"][0]["mass"] = -1' 'mass: expected a mass in kg'
bad no-bodies 'del scene["bodies"]' 'bodies: expected an array of 1 to 1000 bodies'
bad unknown-body 'scene["contacts"][0]["body"] = "nobody"' 'body "nobody" is not one of'
bad self-pair 'scene["contacts"][0]["against"] = {"body": "ball", "shape": {"model": "sphere", "radii": [1, 1, 1]}}' 'is not another of the scene'"'"'s bodies'
bad cavity-ellipsoid 'scene["contacts"][0]["shape"] = {"model": "ellipsoid", "radii": [0.1, 0.1, 0.12]}' 'a cavity holds a sphere'
bad small-cavity 'scene["contacts"][0]["against"]["cavity"]["radius"] = 0.05' 'a radius larger than the sphere'
bad law 'scene["contacts"][0]["normal_law"]["law"] = "spring"' 'hertz, hunt-crossley or lankarani-nikravesh'
bad inertia 'scene["bodies"][0]["inertia"] = [1, 1, 5]' 'triangle inequality'
bad rows 'scene["output_interval"] = 1e-9' 'more than 1e6 output rows'
bad friction 'scene["contacts"][0]["friction"]["transition_speed"] = 0' 'transition_speed: expected a speed > 0'
bad joint-parent 'scene["bodies"].append({"name": "arm", "mass": 1, "inertia": [1, 1, 1], "joint": {"parent": "leg", "point_in_parent": [0, 0, 0], "point_in_child": [0, 0, 0], "axis": [0, 1, 0]}})' 'parent "leg" is not a body listed before this one'
bad hinged-position 'scene["bodies"].append({"name": "arm", "mass": 1, "inertia": [1, 1, 1], "position": [0, 0, 1], "joint": {"parent": "ball", "point_in_parent": [0, 0, 0], "point_in_child": [0, 0, 0], "axis": [0, 1, 0]}})' '"position" of a hinged body'
bad joint-axis 'scene["bodies"].append({"name": "arm", "mass": 1, "inertia": [1, 1, 1], "joint": {"parent": "ball", "point_in_parent": [0, 0, 0], "point_in_child": [0, 0, 0], "axis": [0, 0, 0]}})' 'axis: expected a non-zero vector'
bad tight-cavity 'cavity = scene["contacts"][0]["against"]["cavity"]; del cavity["radius"]; cavity["radii"] = [0.2, 1, 1]' 'holds the sphere'
bad radius-and-radii 'scene["contacts"][0]["against"]["cavity"]["radii"] = [1, 1, 1]' 'unknown key "radius"'
bad misspelt-damping 'scene["contacts"][0]["normal_law"]["disipation"] = 0.5' 'unknown key "disipation"'
bad deep-stray-key 'scene["notes"] = [[[[[[[[1]]]]]]]]' 'unknown key "notes"'
bad missing-fits 'scene["contacts"][0]["shape"] = {"model": "sphere", "fits": "no-such-fits.json"}' 'cannot open'
bad point-in-cavity 'c = scene["contacts"][0]; del c["shape"]; c["point"] = [0, 0, -0.1]' 'a contact point meets a plane only'
bad nan-position 'scene["bodies"][0]["position"] = [0.9, "x", 1]' 'position: expected three numbers'
printf '[%.0s' $(seq 1 100000) > "$tmp/deep.json"
expect_rc 3 "$bin/articula" simulate -i "$tmp/deep.json" -o "$tmp/out-deep"
[ "$(wc -c < "$tmp/err")" -lt 2000 ] || fail "a deep document is echoed"
echo "not json" > "$tmp/text.json"
expect_rc 3 "$bin/articula" simulate -i "$tmp/text.json" -o "$tmp/out-text"
grep -q "is not valid JSON" "$tmp/err" || fail "text scene: $(cat "$tmp/err")"
echo "simulate: ok"
