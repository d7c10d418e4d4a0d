#!/usr/bin/env bash
# A batch study over phantoms of different true shapes, with failing subjects:
# exit 1, the good subjects complete and correct, failures listed with reasons;
# a rerun resumes without redoing anything; Snakemake (local profile) gives
# the same study.csv as articula batch; the same seed gives identical outputs.
# labels: full-size
source "$(dirname "$0")/common.bash"
src=${ARTICULA_SOURCE:?}

# Both subjects at 1.2 mm in-plane voxels, their edges on the steepest fall
# (the blurred-cortex model would triple the runs' time): the test is of the
# study, not of the surface. p2 is read as a DICOM series.
"$bin/articula" phantom -o "$tmp/data/p1" --seed 3 --model ellipsoid --spacing 1.2,1.2,1.5 --no-dicom --quiet
"$bin/articula" phantom -o "$tmp/data/p2" --seed 5 --model sphere --spacing 1.2,1.2,1.5 --quiet
mkdir -p "$tmp/data/bad-dicom"
echo "not a DICOM file" > "$tmp/data/bad-dicom/IM0001"
cat > "$tmp/study.csv" <<CSV
subject,input,joint,side,edge_model
p1,data/p1/phantom.nii.gz,hip,right,steepest
missing,data/nowhere.nii.gz,hip,right,steepest
baddicom,data/bad-dicom,hip,right,steepest
p2,data/p2/dicom,hip,right,steepest
CSV

# --validate finds the two bad inputs without running anything.
set +e
"$bin/articula" batch "$tmp/study.csv" -o "$tmp/study" --validate 2> "$tmp/validate.err"
rc=$?
set -e
[ "$rc" -eq 3 ] || fail "--validate with bad inputs exited $rc, expected 3"
grep -q "subject missing: input .* does not exist" "$tmp/validate.err" || fail "validate names the missing input"
grep -q "subject baddicom: expected DICOM files in .*bad-dicom, found none" "$tmp/validate.err" ||
  fail "validate names the folder without DICOM: $(cat "$tmp/validate.err")"
[ ! -e "$tmp/study/study.csv" ] || fail "--validate ran something"

start=$(date +%s.%N)
set +e
"$bin/articula" batch "$tmp/study.csv" -o "$tmp/study" -j 2 2> "$tmp/batch.err"
rc=$?
set -e
first=$(python3 -c "print(round($(date +%s.%N) - $start, 2))")
[ "$rc" -eq 1 ] || { cat "$tmp/batch.err" >&2; fail "batch with failing subjects exited $rc, expected 1"; }
# Progress: a line per subject with what is done, failed and left.
grep -q "\[4 of 4 done, 2 failed, 0 remaining\]" "$tmp/batch.err" || { cat "$tmp/batch.err" >&2; fail "no final progress line"; }
grep -q "of 4 done, .* remaining, about [0-9]* s left\]" "$tmp/batch.err" || fail "no time estimate in the progress lines"
python3 - "$tmp/study" <<'PY'
import csv, json, sys
study = sys.argv[1]
status = {r["subject"]: r for r in csv.DictReader(open(f"{study}/study_status.csv"))}
assert status["p1"]["status"] == "ok" and status["p2"]["status"] == "ok", status
assert status["missing"]["status"] == "failed" and status["missing"]["exit_code"] == "3", status["missing"]
assert "nowhere" in status["missing"]["message"], status["missing"]
assert status["baddicom"]["status"] == "failed" and status["baddicom"]["exit_code"] == "3", status["baddicom"]
assert status["baddicom"]["message"], status["baddicom"]
rows = list(csv.DictReader(open(f"{study}/study.csv")))
assert {r["subject"] for r in rows} == {"p1", "p2"}, rows
models = {"sphere", "ellipsoid", "superellipsoid", "ovoid", "superovoid"}
for s in ("p1", "p2"):
    assert {r["model"] for r in rows if r["subject"] == s} == models
    truth = json.load(open(f"{study}/../data/{s}/truth.json"))
    for r in rows:
        if r["subject"] != s:
            continue
        centre = [float(r[k]) for k in ("t1_mm", "t2_mm", "t3_mm")]
        err = sum((a - b) ** 2 for a, b in zip(centre, truth["head_center_mm"])) ** 0.5
        # An egg shape's origin trades against its egg terms: on a sphere, a
        # superovoid's c1 of 0.05 fitted to the surface's noise moves it 1.5 mm.
        assert err < (3.0 if "ovoid" in r["model"] else 1.5), (s, r["model"], err)
        assert float(r["rms_mm"]) < 0.5, (s, r["model"], r["rms_mm"])
        # The semi-axes through the centre: a c0x for an ovoid, else a.
        want = float(r["a_mm"]) * (float(r["c0x"]) if r["c0x"] else 1.0)
        assert abs(float(r["semi_axis_a_mm"]) - want) <= 1e-6 * want, (s, r["model"], r["semi_axis_a_mm"], want)
        assert r["determined"] in ("0", "1") and (r["selected"] != "1" or r["determined"] == "1"), r
summary = {r["model"]: r for r in csv.DictReader(open(f"{study}/study_summary.csv"))}
assert set(summary) == models and summary["sphere"]["n_subjects"] == "2"
assert summary["ellipsoid"]["wilcoxon_p_vs_sphere"] != ""
# Per step of the hierarchy: the subjects needing the richer model, the
# cohort's tests, agreeing with each subject's own step in study.csv.
steps = {(r["simpler"], r["richer"]): r for r in csv.DictReader(open(f"{study}/study_steps.csv"))}
assert set(steps) == {("sphere", "ellipsoid"), ("ellipsoid", "superellipsoid"), ("ellipsoid", "ovoid"),
                      ("superellipsoid", "superovoid"), ("ovoid", "superovoid")}, steps
needed = sum(r["richer_needed"] == "1" for r in rows if r["model"] == "ellipsoid")
assert steps[("sphere", "ellipsoid")]["subjects"] == "2" and int(steps[("sphere", "ellipsoid")]["richer_needed"]) == needed, steps
assert 0 <= float(steps[("sphere", "ellipsoid")]["fisher_p"]) <= 1 and 0 < float(steps[("sphere", "ellipsoid")]["sign_test_p"]) <= 1
assert all(r["n_eff"] and 0 < float(r["n_eff"]) <= float(r["n_points"]) for r in rows), rows
# study.svg: one line per good subject, one dot per subject x model, the means of study_summary.csv.
import re
svg = open(f"{study}/study.svg").read()
assert svg.count('<g class="subject">') == 2, svg.count('<g class="subject">')
assert svg.count("</circle>") == len(rows), (svg.count("</circle>"), len(rows))
means = {m: (float(v), int(n)) for m, v, n in re.findall(r"<title>mean (\w+): ([-0-9.e]+) mm \((\d+) subjects\)", svg)}
assert set(means) == models, means
for m, (v, n) in means.items():
    assert abs(v - float(summary[m]["rms_mean_mm"])) <= 0.005 * float(summary[m]["rms_mean_mm"]), (m, v, summary[m])
    assert n == 2
# study.html: the failed subjects with their reasons, every link resolving
# inside the study folder, a dot per subject linking to its report.html.
import os
html = open(f"{study}/study.html").read()
assert not re.search(r"<(link|img|iframe)\b|<script[^>]*\bsrc=", html), "external content"
links = re.findall(r'href="([^"]*)"', html)
for link in links:
    assert not re.match(r"[a-z]+:", link) and os.path.exists(os.path.join(study, link)), link
for s in ("missing", "baddicom"):
    row = re.search(r'<tr class="failed"><td>.*?%s.*?</tr>' % s, html)
    assert row and status[s]["message"][:40].replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;").replace("'", "&#39;") in row.group(0), s
assert re.search(r'<span id="failed">2</span>', html)
assert 'id="cohort-steps"' in html and "Semi-axis a of the selected model" in html, "cohort steps or semi-axis plots missing"
for s in ("p1", "p2"):
    assert html.count('href="subjects/%s/report.html"' % s) >= 5, s  # one dot per RMS plot at least
    assert os.path.exists(f"{study}/subjects/{s}/report.html")
PY

# A rerun resumes: nothing is redone, and it is fast.
start=$(date +%s.%N)
set +e
"$bin/articula" batch "$tmp/study.csv" -o "$tmp/study" -j 2 2> "$tmp/rerun.err"
set -e
second=$(python3 -c "print(round($(date +%s.%N) - $start, 2))")
grep -q "2 ok (2 from an earlier run)" "$tmp/rerun.err" || { cat "$tmp/rerun.err" >&2; fail "rerun did not resume"; }
echo "batch: first run ${first}s, rerun ${second}s"

# Snakemake, local profile, on the good subjects: the same study.csv.
if command -v snakemake > /dev/null; then
  # Stage options as manifest columns (the sample's and the report's): both
  # runners must pass them on, from the one stage table.
  grep -v -e missing -e baddicom "$tmp/study.csv" | sed -e '1s/$/,ball_radius,selection_alpha/' -e '2,$s/$/,1.2,0/' \
    > "$tmp/good.csv"
  # An out-of-range stage option is refused by --validate, naming the stage.
  sed -e '2s/,0$/,5/' "$tmp/good.csv" > "$tmp/bad-option.csv"
  set +e
  "$bin/articula" batch "$tmp/bad-option.csv" -o "$tmp/bad-option" --validate 2> "$tmp/bad-option.err"
  rc=$?
  set -e
  [ "$rc" -eq 3 ] || { cat "$tmp/bad-option.err" >&2; fail "--validate with --selection-alpha 5 exited $rc, expected 3"; }
  grep -q "the report stage: --selection-alpha" "$tmp/bad-option.err" || fail "validate names the stage: $(cat "$tmp/bad-option.err")"
  "$bin/articula" batch "$tmp/good.csv" -o "$tmp/batch-good" -j 2 --quiet
  snakemake -s "$src/pipelines/Snakefile" --profile "$src/pipelines/profiles/local" --quiet \
    --config manifest="$tmp/good.csv" study="$tmp/snake" bin="$bin" > "$tmp/snake.log" 2>&1 ||
    { tail -30 "$tmp/snake.log" >&2; fail "snakemake failed"; }
  diff "$tmp/batch-good/study.csv" "$tmp/snake/study.csv" || fail "snakemake study.csv differs from batch"
  diff "$tmp/batch-good/study_summary.csv" "$tmp/snake/study_summary.csv" || fail "study_summary.csv differs"
  [ "$(grep -c '<g class="subject">' "$tmp/snake/study.svg")" -eq 2 ] || fail "snakemake study.svg"
  grep -q "subjects/p1/report.html" "$tmp/snake/study.html" || fail "snakemake study.html does not link the subjects' reports"
  [ -s "$tmp/snake/subjects/p1/scene.mrml" ] || fail "snakemake wrote no scene.mrml"
  [ -s "$tmp/snake/subjects/p1/errors/error_map.svg" ] || fail "snakemake error_map.svg"
  # The columns took effect: a level of 0 selects the sphere, and a wider
  # open ball keeps fewer points than the first batch's default.
  for subject in p1 p2; do
    grep -q '"selected_model": "sphere"' "$tmp/snake/subjects/$subject/results.json" || fail "snakemake: selection_alpha ignored"
    [ "$(wc -c < "$tmp/snake/subjects/$subject/points.ply")" -lt "$(wc -c < "$tmp/study/subjects/$subject/points.ply")" ] ||
      fail "snakemake: ball_radius ignored"
  done
  # Same seed, same outputs: batch (one process per subject) and Snakemake
  # (one per stage), subject p2, point by point and fit by fit.
  cmp "$tmp/batch-good/subjects/p2/points.ply" "$tmp/snake/subjects/p2/points.ply" || fail "same seed, different points"
  cmp "$tmp/batch-good/subjects/p2/results.csv" "$tmp/snake/subjects/p2/results.csv" || fail "snakemake and batch, different fits"
  # A reviewer excludes p1 (ratings.csv in the study folder): the Snakefile
  # gathers the study again, and batch --gather-only gives the same tables.
  printf 'subject,decision,note\np1,exclude,"motion, rescanned"\np2,include,\n' | tee "$tmp/snake/ratings.csv" \
    > "$tmp/batch-good/ratings.csv"
  snakemake -s "$src/pipelines/Snakefile" --profile "$src/pipelines/profiles/local" --quiet \
    --config manifest="$tmp/good.csv" study="$tmp/snake" bin="$bin" > "$tmp/snake-rated.log" 2>&1 ||
    { tail -30 "$tmp/snake-rated.log" >&2; fail "snakemake after the ratings"; }
  "$bin/articula" batch "$tmp/good.csv" -o "$tmp/batch-good" --gather-only --quiet
  diff "$tmp/batch-good/study.csv" "$tmp/snake/study.csv" || fail "rated: snakemake study.csv differs from batch"
  ! grep -q '^p1,' "$tmp/snake/study.csv" || fail "the excluded p1 is still in study.csv"
  grep -q '^p2,' "$tmp/snake/study.csv" || fail "p2 is missing from study.csv"
  grep -q '^p1,ok,0,.*,exclude,"motion, rescanned"$' "$tmp/snake/study_status.csv" ||
    fail "study_status.csv does not record the exclusion: $(cat "$tmp/snake/study_status.csv")"
  grep -q '"excluded": 1' "$tmp/snake/study.json" || fail "study.json does not count the excluded"
  grep -q '<td>p1</td><td>motion, rescanned</td>' "$tmp/snake/study.html" || fail "study.html does not list p1 as excluded"
  # A decision the study does not know: refused, the line named.
  printf 'subject,decision,note\np1,maybe,\n' > "$tmp/batch-good/ratings.csv"
  expect_rc 3 "$bin/articula" batch "$tmp/good.csv" -o "$tmp/batch-good" --gather-only
  grep -q "ratings.csv' line 2: expected the decision include or exclude, found 'maybe'" "$tmp/err" ||
    fail "a bad decision: $(cat "$tmp/err")"
else
  echo "snakemake not installed: Snakemake comparison skipped" >&2
fi
echo "study: ok"
