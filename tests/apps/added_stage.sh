#!/usr/bin/env bash
# A stage added by one file (added_stage/radii_stage.cpp: its settings, row,
# command and registration line), linked into the driver
# $ARTICULA_ADDED_STAGE_BIN/articula, takes its place with no other edit:
# `articula stages --json` lists it after the stage that writes its input;
# `run --help` shows its option and default; `run` runs it with the option
# given to run and skips it when it is up to date; a manifest column sets
# it; the Snakemake workflow makes a rule of it and writes the same file.
# The runs put the edges on the steepest fall and fit the sphere alone (the
# stage reads whatever fits.json holds; the rest would take most of the time).
source "$(dirname "$0")/common.bash"
src=${ARTICULA_SOURCE:?}
added_bin=${ARTICULA_ADDED_STAGE_BIN:?}
articula="$added_bin/articula"

"$articula" stages --json > "$tmp/stages.json"
python3 - "$tmp/stages.json" <<'PY'
import json, sys
stages = json.load(open(sys.argv[1]))["stages"]
names = [s["name"] for s in stages]
assert names[:6] == ["segment", "mesh", "sample", "fit", "errors", "report"], names
assert "radii" in names and names.index("radii") > names.index("fit"), names
radii = stages[names.index("radii")]
assert radii["inputs"] == ["fits.json"] and radii["outputs"] == ["radii.csv"], radii
option = radii["options"][0]
assert (option["name"], option["type"], option["default"], option["above"], option["max"]) == ("radii-scale", "number", 1.0, 0, 1000), option
PY
"$articula" run --help > "$tmp/help"
grep -q -- "--radii-scale NUMBER=1 .*\[radii\] Factor on every semi-axis (above 0, up to 1000)" "$tmp/help" ||
  fail "run --help does not show --radii-scale with its default and range"
# The driver without the stage knows nothing of it.
expect_rc 2 "$bin/articula" run -i x -o "$tmp/none" --radii-scale 2

"$bin/articula" phantom -o "$tmp/p" --seed 4 --model ellipsoid --spacing 1.5,1.5,2 --no-dicom --quiet
"$articula" run -i "$tmp/p/phantom.nii.gz" -o "$tmp/run" --edge-model steepest --models sphere --radii-scale 2 --quiet
# Each model's semi-axes in fits.json, times the factor.
check_radii() {
  python3 - "$tmp/run" "$1" <<'PY'
import csv, json, sys
run, scale = sys.argv[1], float(sys.argv[2])
fits = {m["model"]: m["radii_mm"] for m in json.load(open(f"{run}/fits.json"))["models"]}
rows = list(csv.DictReader(open(f"{run}/radii.csv")))
assert [r["model"] for r in rows] == list(fits), rows
for r in rows:
    for axis, radius in zip("abc", fits[r["model"]]):
        assert abs(float(r[f"{axis}_mm"]) - scale * radius) < 1e-9 * radius, (r, radius)
PY
}
check_radii 2
# Up to date (at another verbosity too): nothing runs again; another factor
# reruns the stage alone.
"$articula" run -i "$tmp/p/phantom.nii.gz" -o "$tmp/run" --edge-model steepest --models sphere --radii-scale 2 2> "$tmp/again.err"
[ "$(grep -c "run: [a-z]* is up to date" "$tmp/again.err")" -eq 7 ] || { cat "$tmp/again.err" >&2; fail "a second run redid stages"; }
"$articula" run -i "$tmp/p/phantom.nii.gz" -o "$tmp/run" --edge-model steepest --models sphere --radii-scale 3 2> "$tmp/third.err"
[ "$(grep "run: \[" "$tmp/third.err")" = "articula: run: [7/7] radii ..." ] ||
  { cat "$tmp/third.err" >&2; fail "a new --radii-scale did not rerun the radii stage alone"; }
check_radii 3

# A manifest column: checked against the stage's declaration, then used.
printf 'subject,input,joint,side,edge_model,models,radii_scale\np1,%s,hip,right,steepest,sphere,5000\n' "$tmp/p/phantom.nii.gz" > "$tmp/bad.csv"
expect_rc 3 "$articula" batch "$tmp/bad.csv" -o "$tmp/bad" --validate
grep -q -- "column .radii_scale.: the radii stage: --radii-scale: expected above 0, up to 1000, found 5000" "$tmp/err" || fail "the manifest's radii_scale: $(cat "$tmp/err")"
printf 'subject,input,joint,side,edge_model,models,radii_scale\np1,%s,hip,right,steepest,sphere,3\n' "$tmp/p/phantom.nii.gz" > "$tmp/study.csv"

if ! command -v snakemake > /dev/null; then fail "snakemake is not installed (scripts/install-deps.sh)"; fi
snakemake -s "$src/pipelines/Snakefile" --profile "$src/pipelines/profiles/local" --quiet \
  --config manifest="$tmp/study.csv" study="$tmp/snake" bin="$added_bin" > "$tmp/snake.log" 2>&1 ||
  { tail -30 "$tmp/snake.log" >&2; fail "snakemake failed"; }
cmp "$tmp/run/radii.csv" "$tmp/snake/subjects/p1/radii.csv" || fail "snakemake's radii.csv differs from run's"
echo "added stage: in stages --json, run, a manifest column and the Snakefile"
