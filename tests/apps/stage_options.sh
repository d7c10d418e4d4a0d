#!/usr/bin/env bash
# Every stage option, from `articula stages --json`: its stage's command
# takes it (the line parses, then the missing input stops the stage: exit
# 3, not a usage error), `articula run` takes it under its run name and
# passes it to the stage (--dry-run shows the stage's command line), and
# `run --help` lists it with its default. Then a run with options the user
# guide names for run (the segment's and the sample's head radii, the
# midline margin, the surface level, the sample's band, the fit's sample
# size) on a small phantom: each stage records the value it was given.
source "$(dirname "$0")/common.bash"

"$bin/articula" phantom -o "$tmp/p" --seed 3 --spacing 1.5,1.5,2 --no-dicom --quiet
ct="$tmp/p/phantom.nii.gz"
"$bin/articula" stages --json > "$tmp/stages.json"
"$bin/articula" run --help > "$tmp/run-help.txt"

python3 - "$bin" "$ct" "$tmp" <<'PY'
import json, os, re, subprocess, sys
bin, ct, tmp = sys.argv[1:]
stages = json.load(open(os.path.join(tmp, "stages.json")))["stages"]
help_text = open(os.path.join(tmp, "run-help.txt")).read()
missing = os.path.join(tmp, "missing")
# Each stage's command line from the table, its inputs missing.
def wiring(stage):
    fields = {"{CT}": missing, "{folder}": os.path.join(tmp, "missing-folder"), "{joint}": "hip", "{side}": "right"}
    args = []
    for a in stage["arguments"]:
        for key, value in fields.items():
            a = a.replace(key, value)
        args.append(a)
    return args
# Values for the options without a default.
examples = {"seed-point": "1,2,3", "roi": "-60,-60,-60,60,60,60", "series-uid": "1.2.3",
            "label": f"{tmp}/femur.nii.gz", "bounds": f"{tmp}/bounds.json"}

def articula(*args):
    return subprocess.run([os.path.join(bin, "articula"), *args], capture_output=True, text=True)

def as_text(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list):
        return ",".join(as_text(v) for v in value)
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)

# Every option at once: each stage's command takes all of its own, and one
# dry run takes every stage's (a process each, not two per option: under the
# sanitizers a start costs most of a second).
count, run_given, run_names, checks = 0, [], set(), []
for stage in stages:
    given_all = []
    for o in stage["options"]:
        name, run_name, kind = o["name"], o["run_name"], o["type"]
        assert kind in ("number", "integer", "flag", "text", "file", "choice", "numbers", "choices"), o
        assert o["help"], o
        value = examples.get(name) if o["default"] in ("", []) else as_text(o["default"])
        assert value is not None, f"no value to try for {stage['name']} --{name}"
        given = [f"--{name}"] if kind == "flag" else [f"--{name}", value]
        given_all += given
        if run_name not in run_names:
            run_names.add(run_name)
            run_given += [f"--{run_name}"] if kind == "flag" else [f"--{run_name}", value]
        checks.append((stage["name"], run_name, kind, given))
        # run --help: the option, with its default where it has one.
        line = re.search(r"^\s*--%s(?: [A-Z]+(?: x \d+)?)?(?:=(\S+))?\s" % re.escape(run_name), help_text, re.M)
        assert line, f"run --help does not list --{run_name}"
        if kind != "flag" and o["default"] not in ("", []):
            assert line.group(1) == as_text(o["default"]), (run_name, line.group(0))
        count += 1
    # The stage's own command: the line parses, then the missing input stops it.
    r = articula(stage["name"], *wiring(stage), *given_all)
    assert r.returncode == 3, (stage["name"], given_all, r.returncode, r.stderr)
# run, under the run names: each stage gets its options, under its own names,
# and no stage gets an option that is not its own.
r = articula("run", "-i", ct, "-o", f"{tmp}/dry", "--dry-run", "--json", *run_given)
assert r.returncode == 0, (run_given, r.stderr)
plan = {s["stage"]: s["arguments"] for s in json.loads(r.stdout)["stages"]}
for stage_name, run_name, kind, given in checks:
    args = plan[stage_name]
    assert given[0] in args and (kind == "flag" or args[args.index(given[0]) + 1] == given[1]), (given, args)
for stage in stages:
    common = {"--seed", "--threads", "--force", "--quiet", "--verbose"}  # every command's
    own = {f"--{o['name']}" for o in stage["options"]} | {a for a in stage["arguments"] if a.startswith("-")} | common
    strays = [a for a in plan[stage["name"]] if a.startswith("--") and a not in own]
    assert not strays, (stage["name"], strays)
assert not os.path.exists(f"{tmp}/dry"), "a dry run wrote"
print(f"{count} stage options: taken by their stages and by run, listed in run --help")
assert count >= 44, count
PY

# Options the user guide lists for run, on a real run: each stage's sidecar
# records what it was given (the edges on the steepest fall and the sphere
# alone fitted, which the options do not touch: a third of the time).
expect_rc 0 "$bin/articula" run -i "$ct" -o "$tmp/r" --min-radius 12 --max-radius 40 --midline-margin 0 \
  --surface-hu 350 --band 1.5 --sample-points 0 --errors-band 0.25 --edge-model steepest --models sphere --quiet
python3 - "$tmp/r" <<'PY'
import json, sys
folder = sys.argv[1]
seg = json.load(open(f"{folder}/label.nii.gz.json"))["provenance"]["parameters"]
assert (seg["min_radius_mm"], seg["max_radius_mm"], seg["midline_margin_mm"], seg["surface_hu"]) == (12, 40, 0, 350), seg
sample = json.load(open(f"{folder}/points.ply.json"))["provenance"]["parameters"]
assert (sample["min_radius_mm"], sample["max_radius_mm"], sample["band_mm"]) == (12, 40, 1.5), sample
assert json.load(open(f"{folder}/fits.json"))["provenance"]["parameters"]["sample_points"] == 0
assert json.load(open(f"{folder}/errors/summary.json"))["provenance"]["parameters"]["band_mm"] == 0.25
assert json.load(open(f"{folder}/results.json"))["qc"]["status"] in ("pass", "warn")
PY

# Out of range: refused before any stage, the stage and the range named.
expect_rc 2 "$bin/articula" run -i "$ct" -o "$tmp/r2" --min-radius 70
grep -q "the segment stage: --min-radius (mm): expected 1 to 60, found 70" "$tmp/err" || fail "min-radius: $(cat "$tmp/err")"
expect_rc 2 "$bin/articula" run -i "$ct" -o "$tmp/r2" --edge-model sharp
grep -q "the mesh stage: --edge-model: expected auto, cortex, steepest, found 'sharp'" "$tmp/err" ||
  fail "edge-model: $(cat "$tmp/err")"
[ ! -e "$tmp/r2" ] || fail "run wrote before refusing an option"
echo "stage options: ok"
