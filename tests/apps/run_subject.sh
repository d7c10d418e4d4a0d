#!/usr/bin/env bash
# pipelines/run-subject.sh, the shell chain of the stage programs that users
# copy, gives what `articula run` gives on the same small phantom: the same
# results.json (the fitted parameters and errors of every model, the
# selection, the head's checks and their values) apart from provenance, and
# the same stage outputs where they carry no timing.
source "$(dirname "$0")/common.bash"
src=${ARTICULA_SOURCE:?}

"$bin/articula" phantom -o "$tmp/p" --seed 11 --spacing 1.2,1.2,1.5 --side left --no-dicom --quiet
ct="$tmp/p/phantom.nii.gz"
ARTICULA_BIN="$bin" bash "$src/pipelines/run-subject.sh" "$ct" "$tmp/script" hip left > "$tmp/script.log" 2>&1 ||
  { cat "$tmp/script.log" >&2; fail "run-subject.sh failed"; }
grep -q "done: $tmp/script/results.json" "$tmp/script.log" || fail "run-subject.sh: $(tail -3 "$tmp/script.log")"
expect_rc 0 "$bin/articula" run -i "$ct" -o "$tmp/run" --joint hip --side left --quiet

python3 - "$tmp/script" "$tmp/run" <<'PY'
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
print(f"run-subject.sh and run agree: selected {a['selected_model']}, qc {a['qc']['status']}, "
      f"{len(a['qc']['checks'])} checks, {len(a['models'])} models")
PY
for file in label.nii.gz points.ply errors/errors.csv results.csv; do
  cmp "$tmp/script/$file" "$tmp/run/$file" || fail "$file differs between run-subject.sh and run"
done
echo "run-subject: ok"
