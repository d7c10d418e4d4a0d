#!/usr/bin/env bash
# A batch killed in the middle of a subject (SIGKILL to its whole process
# group, as a cluster's preemption or a closed terminal does) resumes: the
# finished subject is not redone, the interrupted one is redone from
# scratch, no temporary file is left behind, and the study tables equal
# those of an uninterrupted batch. The study selects each phantom's true
# model (sphere, ellipsoid, superellipsoid) as the one its points support.
# labels: full-size
source "$(dirname "$0")/common.bash"

models=(sphere ellipsoid superellipsoid)
# The edges on the steepest fall: the blurred-cortex model's point-spread
# estimate (the default on these voxels) would take each of the nine runs
# from about 2 s to 10 s, and nothing here depends on it. Isotropic voxels:
# on long slices the steepest fall's offset depends on the surface's
# direction to them, which a sphere's points show as an ellipsoid's shape.
echo "subject,input,joint,side,edge_model" > "$tmp/study.csv"
for i in 1 2 3; do
  "$bin/articula" phantom -o "$tmp/data/s$i" --seed $((20 + i)) --model "${models[$((i - 1))]}" --spacing 1.2,1.2,1.2 \
    --no-dicom --quiet
  echo "s$i,data/s$i/phantom.nii.gz,hip,right,steepest" >> "$tmp/study.csv"
done
"$bin/articula" batch "$tmp/study.csv" -o "$tmp/reference" -j 1 --quiet

setsid "$bin/articula" batch "$tmp/study.csv" -o "$tmp/killed" -j 1 --quiet 2> "$tmp/killed.err" &
pid=$!
for _ in $(seq 1 1200); do
  [ -e "$tmp/killed/subjects/s1/status.json" ] && break
  sleep 0.25
done
[ -e "$tmp/killed/subjects/s1/status.json" ] || fail "subject s1 did not finish within 5 minutes"
sleep 0.5  # s2 is now under way (a run takes about 2 s)
kill -KILL -- "-$pid"
wait "$pid" || true
[ ! -e "$tmp/killed/subjects/s2/status.json" ] || fail "s2 finished before the kill: nothing was interrupted"
[ ! -e "$tmp/killed/study.csv" ] || fail "a killed batch left study.csv looking complete"
cp "$tmp/killed/subjects/s1/status.json" "$tmp/s1-status.json"
cp "$tmp/killed/subjects/s1/results.json" "$tmp/s1-results.json"

"$bin/articula" batch "$tmp/study.csv" -o "$tmp/killed" -j 1 2> "$tmp/resume.err" ||
  { cat "$tmp/resume.err" >&2; fail "the resumed batch failed"; }
grep -q "3 ok (1 from an earlier run)" "$tmp/resume.err" || { cat "$tmp/resume.err" >&2; fail "s1 was redone"; }
cmp "$tmp/s1-status.json" "$tmp/killed/subjects/s1/status.json" || fail "s1's status changed"
cmp "$tmp/s1-results.json" "$tmp/killed/subjects/s1/results.json" || fail "s1's results changed"
leftovers=$(find "$tmp/killed" -name '.articula-tmp-*')
[ -z "$leftovers" ] || fail "temporary files left behind: $leftovers"
diff "$tmp/reference/study.csv" "$tmp/killed/study.csv" || fail "study.csv differs from an uninterrupted batch"
diff "$tmp/reference/study_summary.csv" "$tmp/killed/study_summary.csv" || fail "study_summary.csv differs"
python3 - "$tmp/killed" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(f"{sys.argv[1]}/study.csv")))
selected = {r["subject"]: r["model"] for r in rows if r["selected"] == "1"}
assert {r["qc_status"] for r in rows} == {"pass"}, [(r["subject"], r["qc_status"], r["qc_reasons"]) for r in rows]
assert selected == {"s1": "sphere", "s2": "ellipsoid", "s3": "superellipsoid"}, selected
summary = {r["model"]: r for r in csv.DictReader(open(f"{sys.argv[1]}/study_summary.csv"))}
assert [summary[m]["times_selected"] for m in ("sphere", "ellipsoid", "superellipsoid", "ovoid", "superovoid")] == \
    ["1", "1", "1", "0", "0"], summary
PY
# A new --selection-alpha reruns only the report: at 0 no richer model
# passes its test, and the superellipsoid phantom's points select the sphere.
dir="$tmp/killed/subjects/s3"
read -r input seed < <(python3 -c '
import json, sys
a = json.load(open(sys.argv[1]))["args"]
print(a[a.index("-i") + 1], a[a.index("--seed") + 1])' "$dir/.articula/segment.json")
"$bin/articula" run -i "$input" -o "$dir" --joint hip --side right --seed "$seed" --threads 1 --edge-model steepest \
  --selection-alpha 0 2> "$tmp/tolerance.err" || { cat "$tmp/tolerance.err" >&2; fail "run --selection-alpha failed"; }
for stage in segment mesh sample fit errors; do
  grep -q "run: $stage is up to date" "$tmp/tolerance.err" || { cat "$tmp/tolerance.err" >&2; fail "$stage was redone"; }
done
grep -q "run: \[6/6\] report \.\.\." "$tmp/tolerance.err" || { cat "$tmp/tolerance.err" >&2; fail "the report was not redone"; }
python3 - "$dir/results.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["selection"]["alpha"] == 0, r["selection"]
assert r["selected_model"] == "sphere", r["selected_model"]
assert r["least_rms_model"] != "sphere", r["least_rms_model"]
assert not any(s["richer_needed"] for s in r["selection"]["path"]), r["selection"]["path"]
PY
echo "killed batch resumed: ok"
