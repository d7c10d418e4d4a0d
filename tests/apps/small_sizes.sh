#!/usr/bin/env bash
# Every stage and the drivers end to end on a small CT (a coarse-voxel
# phantom, 1.2 x 1.2 x 1.5 mm, seconds in a release build), so that
# the sanitizer tier runs them all, on the phantom's DICOM series: the stage
# programs chained by pipelines/run-subject.sh (the shell pipeline users
# copy); a batch of two subjects, one failing, whose good subject goes
# through `articula run`. Each result is checked against the phantom's
# truth, and the shell pipeline's against the batch's subject run with the
# same settings: the same results.json apart from provenance, the same stage
# outputs where they carry no timing. Both put the edges on the steepest fall
# (a third of the blurred-cortex model's time; that model, the default
# here, runs in the sphere fixture).
source "$(dirname "$0")/common.bash"
src=${ARTICULA_SOURCE:?}

"$bin/articula" phantom -o "$tmp/p" --seed 8 --model ovoid --spacing 1.2,1.2,1.5 --quiet
ct="$tmp/p/dicom"

# check_head RESULTS: the sphere's centre within 1 mm of the true head's,
# the selected model's RMS under 0.3 mm, the checks passed or warned.
check_head() {
  python3 - "$1" "$tmp/p/truth.json" <<'PY'
import json, math, sys
r, truth = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
sphere = next(m for m in r["models"] if m["model"] == "sphere")
centre = [sphere["parameters"][k] for k in ("t1_mm", "t2_mm", "t3_mm")]
err = math.dist(centre, truth["head_center_mm"])
selected = next(m for m in r["models"] if m["model"] == r["selected_model"])
print(f"{sys.argv[1]}: sphere centre {err:.2f} mm from the truth, selected {r['selected_model']} "
      f"(true {truth['model']}), RMS {selected['errors']['rms_mm']:.3f} mm, qc {r['qc']['status']}")
assert err < 1.0, err
assert selected["errors"]["rms_mm"] < 0.3, selected["errors"]
assert r["qc"]["status"] in ("pass", "warn"), r["qc"]
PY
}

# The stage programs, chained by the shell pipeline.
s="$tmp/stages"
ARTICULA_BIN="$bin" bash "$src/pipelines/run-subject.sh" "$ct" "$s" hip right steepest > "$tmp/script.log" 2>&1 ||
  { cat "$tmp/script.log" >&2; fail "run-subject.sh failed"; }
grep -q "done: $s/results.json" "$tmp/script.log" || fail "run-subject.sh: $(tail -3 "$tmp/script.log")"
check_head "$s/results.json"

# A batch of two subjects, one whose input is missing: exit 1, the good one
# complete and right, the study tables written.
cat > "$tmp/study.csv" <<CSV
subject,input,joint,side,edge_model
small,p/dicom,hip,right,steepest
missing,p/nowhere.nii.gz,hip,right,steepest
CSV
expect_rc 1 "$bin/articula" batch "$tmp/study.csv" -o "$tmp/study" -j 2 --quiet
check_head "$tmp/study/subjects/small/results.json"
[ -s "$tmp/study/subjects/small/report.html" ] && [ -s "$tmp/study/subjects/small/scene.mrml" ] ||
  fail "run wrote no report or scene"
grep -q "^missing,failed,3," "$tmp/study/study_status.csv" || fail "the missing subject: $(cat "$tmp/study/study_status.csv")"
[ "$(grep -c '^small,' "$tmp/study/study.csv")" -eq 5 ] || fail "study.csv: not one row per model"
[ -s "$tmp/study/study.html" ] || fail "no study.html"

# The shell pipeline and batch's run of the same CT and settings agree.
small="$tmp/study/subjects/small"
python3 - "$s" "$small" <<'PY'
import json, sys
script, run = sys.argv[1:]

def without(value, keys):
    """The JSON without the named keys at any depth (what differs by design)."""
    if isinstance(value, dict):
        return {k: without(v, keys) for k, v in value.items() if k not in keys}
    if isinstance(value, list):
        return [without(v, keys) for v in value]
    return value

a, b = (json.load(open(f"{folder}/results.json")) for folder in (script, run))
assert a["selected_model"] == b["selected_model"] and a["qc"] == b["qc"], (a["qc"], b["qc"])
assert [m["parameters"] for m in a["models"]] == [m["parameters"] for m in b["models"]], "fitted parameters differ"
assert [m["errors"] for m in a["models"]] == [m["errors"] for m in b["models"]], "errors differ"
timing = {"provenance", "seconds", "libraries"}
assert without(a, timing) == without(b, timing), "results.json differs"
for name in ("fits.json", "errors/summary.json"):
    x, y = (without(json.load(open(f"{folder}/{name}")), timing | {"input"}) for folder in (script, run))
    assert x == y, name
print(f"run-subject.sh and batch agree: selected {a['selected_model']}, qc {a['qc']['status']}, "
      f"{len(a['qc']['checks'])} checks, {len(a['models'])} models")
PY
for file in label.nii.gz points.ply errors/errors.csv results.csv; do
  cmp "$s/$file" "$small/$file" || fail "$file differs between run-subject.sh and batch"
done
echo "small sizes: ok"
