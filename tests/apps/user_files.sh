#!/usr/bin/env bash
# No command deletes or replaces a file it did not write: outputs that exist
# are refused by name before any work (exit 2) unless --force, a folder of
# the user's files is refused even with --force, and the clean-up of an
# interrupted run touches only articula's own temporaries. Small CTs, their
# edges on the steepest fall and the sphere alone fitted (the blurred-cortex
# model and the other four fits would take most of the runs' time; the test
# is of files).
source "$(dirname "$0")/common.bash"
fast=(--edge-model steepest --models sphere)

# sums FOLDER: a listing of every file under FOLDER with its checksum.
sums() { (cd "$1" && find . -type f -exec sha256sum {} + | sort); }

# phantom: the user's dicom/ and truth.json are kept, with and without --force.
p="$tmp/p"
mkdir -p "$p/dicom"
echo "the user's notes" > "$p/dicom/notes.txt"
echo '{"mine": true}' > "$p/truth.json"
before=$(sums "$p")
expect_rc 2 "$bin/articula" phantom -o "$p" --spacing 1.5,1.5,2 -q
grep -q "notes.txt.*did not write" "$tmp/err" || fail "phantom: the user's file not named: $(cat "$tmp/err")"
expect_rc 2 "$bin/articula" phantom -o "$p" --spacing 1.5,1.5,2 -q --force
[ "$(sums "$p")" = "$before" ] || fail "phantom changed the user's files"
rm "$p/dicom/notes.txt"
expect_rc 2 "$bin/articula" phantom -o "$p" --spacing 1.5,1.5,2 -q
grep -q "refusing to overwrite .*truth.json" "$tmp/err" || fail "phantom: truth.json not named: $(cat "$tmp/err")"
[ "$(cat "$p/truth.json")" = '{"mine": true}' ] || fail "phantom replaced truth.json without --force"
[ ! -e "$p/phantom.nii.gz" ] || fail "phantom wrote before refusing"
# Its own earlier series is replaced with --force, slice for slice.
expect_rc 0 "$bin/articula" phantom -o "$p" --spacing 1.5,1.5,4 -q --force
slices=$(find "$p/dicom" -name 'slice_*.dcm' | wc -l)
expect_rc 0 "$bin/articula" phantom -o "$p" --spacing 1.5,1.5,2 -q --force
[ "$(find "$p/dicom" -type f | wc -l)" -gt "$slices" ] || fail "the thinner slices' series: $(find "$p/dicom" -type f | wc -l) files"
expect_rc 0 "$bin/articula" phantom -o "$p" --spacing 1.5,1.5,4 -q --force
[ "$(find "$p/dicom" -type f | wc -l)" -eq "$slices" ] || fail "the thicker slices' series kept the earlier slices"
expect_rc 0 "$bin/articula" phantom -o "$p" --spacing 1.5,1.5,2 -q --force
echo "x" > "$tmp/a-file"
expect_rc 2 "$bin/articula" phantom -o "$tmp/a-file" -q
grep -q "is a file: expected a folder" "$tmp/err" || fail "phantom -o FILE: $(cat "$tmp/err")"

# run: a report.html of the user's in the output folder is refused by name
# before any stage; with --force it is replaced.
u="$tmp/u"
mkdir -p "$u"
echo "<p>the user's page</p>" > "$u/report.html"
expect_rc 2 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$u" -q "${fast[@]}"
grep -q "refusing to overwrite .*report.html, which articula run did not write" "$tmp/err" ||
  fail "run: report.html not named: $(cat "$tmp/err")"
[ "$(ls -A "$u")" = "report.html" ] || fail "run wrote before refusing: $(ls -A "$u")"
expect_rc 2 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$tmp/a-file" -q "${fast[@]}"
grep -q "is a file: expected a folder" "$tmp/err" || fail "run -o FILE: $(cat "$tmp/err")"

# run's clean-up: articula's own temporary of a writer that has exited is
# removed; a user's files that look like temporaries are kept, in the output
# folder and in a folder of their own inside it (a pid of 20 digits once
# made every run fail in std::stoll).
r="$tmp/r"
mkdir -p "$r/drafts"
sh -c 'exit 0' & dead=$!
wait "$dead"
echo "draft" > "$r/.tmp-4000000-draft.txt"
echo "draft" > "$r/.articula-tmp-99999999999999999999-x"
echo "draft" > "$r/drafts/.articula-tmp-$dead-draft.txt"
echo "half" > "$r/.articula-tmp-$dead-points.ply"
expect_rc 0 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$r" -q "${fast[@]}"
[ ! -e "$r/.articula-tmp-$dead-points.ply" ] || fail "run left its own stale temporary"
for kept in .tmp-4000000-draft.txt .articula-tmp-99999999999999999999-x "drafts/.articula-tmp-$dead-draft.txt"; do
  [ -e "$r/$kept" ] || fail "run's clean-up deleted the user's $kept"
done
# A second run replaces what the first wrote without --force.
touch "$p/phantom.nii.gz"
expect_rc 0 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$r" -q "${fast[@]}"
# batch: a study.csv of the user's in the study folder is refused by name
# before any subject runs; a batch's own tables are replaced by its rerun.
b="$tmp/b"
mkdir -p "$b"
echo "subject,mine" > "$b/study.csv"
printf 'subject,input,joint,side,edge_model,models\ns1,%s,hip,right,steepest,sphere\n' "$p/phantom.nii.gz" > "$tmp/manifest.csv"
expect_rc 2 "$bin/articula" batch "$tmp/manifest.csv" -o "$b" -q
grep -q "refusing to overwrite .*study.csv, which articula batch did not write" "$tmp/err" ||
  fail "batch: study.csv not named: $(cat "$tmp/err")"
[ "$(ls -A "$b")" = "study.csv" ] && [ "$(cat "$b/study.csv")" = "subject,mine" ] || fail "batch wrote before refusing"
rm "$b/study.csv"
expect_rc 0 "$bin/articula" batch "$tmp/manifest.csv" -o "$b" -q
expect_rc 0 "$bin/articula" batch "$tmp/manifest.csv" -o "$b" -q

# An input that is no file (a link to /dev/zero, a pipe) is refused at once,
# not read for ever to hash it.
ln -s /dev/zero "$tmp/zero.nii"
mkfifo "$tmp/pipe.nii"
for input in "$tmp/zero.nii" "$tmp/pipe.nii"; do
  expect_rc 3 timeout 60 "$bin/articula" run -i "$input" -o "$tmp/z" -q
  grep -q "neither a file nor a folder" "$tmp/err" || fail "run -i $input: $(cat "$tmp/err")"
done
# run: a sidecar of the user's (a stage's provenance .json, a per-model file
# of the errors stage) is refused by name like an output; --force replaces it.
c="$tmp/c"
mkdir -p "$c/errors"
echo '{"mine": true}' > "$c/label.nii.gz.json"
echo "mine" > "$c/errors/points_sphere.vtp"
expect_rc 2 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$c" -q "${fast[@]}"
grep -q "refusing to overwrite .*label.nii.gz.json, .*errors/points_sphere.vtp, which articula run did not write" "$tmp/err" ||
  fail "run: the user's sidecars not named: $(cat "$tmp/err")"
[ "$(cat "$c/label.nii.gz.json")" = '{"mine": true}' ] && [ ! -e "$c/.articula" ] || fail "run wrote before refusing"
expect_rc 0 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$c" -q "${fast[@]}" --force
grep -q '"provenance"' "$c/label.nii.gz.json" || fail "run --force did not replace the sidecar"
expect_rc 0 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$c" -q "${fast[@]}"

# The stage programs check what they write beside their output the same way.
echo '{"mine": true}' > "$tmp/label.nii.gz.json"
expect_rc 2 "$bin/articula-segment" -i "$p/phantom.nii.gz" -o "$tmp/label.nii.gz" -q
grep -q "refusing to overwrite .*label.nii.gz.json (use --force)" "$tmp/err" || fail "segment: $(cat "$tmp/err")"
[ ! -e "$tmp/label.nii.gz" ] || fail "segment wrote before refusing"
expect_rc 0 "$bin/articula-segment" -i "$p/phantom.nii.gz" -o "$tmp/label.nii.gz" -q --force
grep -q '"provenance"' "$tmp/label.nii.gz.json" || fail "segment --force did not replace its sidecar"
cp -r "$c" "$tmp/rep" && rm -r "$tmp/rep/results.json" "$tmp/rep/slicer"
expect_rc 2 "$bin/articula-report" -i "$tmp/rep" --ct "$p/phantom.nii.gz" -q
grep -q "refusing to overwrite .*report.html, .*results.csv, .*scene.mrml (use --force)" "$tmp/err" ||
  fail "report: $(cat "$tmp/err")"
[ ! -e "$tmp/rep/results.json" ] || fail "report wrote before refusing"

# batch: a status.json of the user's in a subject's folder is refused by name.
mkdir -p "$tmp/bs/subjects/s1"
echo '{"mine": true}' > "$tmp/bs/subjects/s1/status.json"
expect_rc 2 "$bin/articula" batch "$tmp/manifest.csv" -o "$tmp/bs" -q
grep -q "refusing to overwrite .*subjects/s1/status.json, which articula batch did not write" "$tmp/err" ||
  fail "batch: status.json not named: $(cat "$tmp/err")"
[ "$(cat "$tmp/bs/subjects/s1/status.json")" = '{"mine": true}' ] || fail "batch replaced the user's status.json"
expect_rc 0 "$bin/articula" batch "$tmp/manifest.csv" -o "$tmp/bs" -q --force
grep -q '"command"' "$tmp/bs/subjects/s1/status.json" || fail "batch --force did not replace status.json"

# One run per output folder: a second run on the folder of a running one is
# refused at once (exit 1) naming the folder and the first's pid, and the
# first completes. The first is paused once it holds the lock, so that it
# cannot finish before the second starts.
l="$tmp/l"
"$bin/articula" run -i "$p/phantom.nii.gz" -o "$l" -q "${fast[@]}" & first=$!
for _ in $(seq 500); do [ -s "$l/.articula/lock" ] && break; sleep 0.02; done
kill -STOP "$first"
expect_rc 1 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$l" -q "${fast[@]}"
kill -CONT "$first"
grep -q "output folder '$l' is in use by articula run (pid $first)" "$tmp/err" || fail "second run: $(cat "$tmp/err")"
wait "$first" || fail "the first run failed beside the refused second"
[ -e "$l/results.json" ] || fail "the first run did not finish"
# A killed run leaves no lock: the next run proceeds (and resumes).
rm -rf "$l"
"$bin/articula" run -i "$p/phantom.nii.gz" -o "$l" -q "${fast[@]}" & killed=$!
for _ in $(seq 500); do [ -s "$l/.articula/lock" ] && break; sleep 0.02; done
kill -9 "$killed"
{ wait "$killed"; } 2>/dev/null && fail "the killed run exited 0" || true
expect_rc 0 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$l" -q "${fast[@]}"
[ -e "$l/results.json" ] || fail "the run after a killed one did not finish"
# batch: one per study folder, the same way (on a copy of b's finished
# study, so that the batch that proceeds resumes its subject).
cp -r "$b" "$tmp/busy"
exec 9>>"$tmp/busy/.articula/lock"
flock 9
expect_rc 1 "$bin/articula" batch "$tmp/manifest.csv" -o "$tmp/busy" -q
grep -q "output folder '$tmp/busy' is in use" "$tmp/err" || fail "batch on a locked study folder: $(cat "$tmp/err")"
exec 9>&-
expect_rc 0 "$bin/articula" batch "$tmp/manifest.csv" -o "$tmp/busy" -q

# A run that fails before writing any output leaves nothing of itself: no
# .articula, and no output folder it made; in a folder of the user's (an
# input DICOM folder) neither.
echo "not a CT" > "$tmp/junk.nii"
expect_rc 3 "$bin/articula" run -i "$tmp/junk.nii" -o "$tmp/new" -q
[ ! -e "$tmp/new" ] || fail "a failed run left its output folder: $(ls -A "$tmp/new")"
mkdir -p "$tmp/mine"
expect_rc 3 "$bin/articula" run -i "$tmp/junk.nii" -o "$tmp/mine" -q
[ -z "$(ls -A "$tmp/mine")" ] || fail "a failed run left: $(ls -A "$tmp/mine")"
expect_rc 2 "$bin/articula" run -i "$p/dicom" -o "$p/dicom" -q
[ ! -e "$p/dicom/.articula" ] || fail "a failed run left .articula in the input DICOM folder"
# One that failed after a stage wrote keeps its stamps: the next resumes.
expect_rc 0 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$tmp/part" --until sample -q "${fast[@]}"
expect_rc 2 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$tmp/part" --models nosuch -q
[ -e "$tmp/part/.articula/sample.json" ] || fail "a failed run removed the stamps of the stages it had done"

echo "user files: ok"
