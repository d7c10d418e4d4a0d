#!/usr/bin/env bash
# No command deletes or replaces a file it did not write: outputs that exist
# are refused by name before any work (exit 2) unless --force, a folder of
# the user's files is refused even with --force, and the clean-up of an
# interrupted run touches only articula's own temporaries. Small CTs.
source "$(dirname "$0")/common.bash"

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
expect_rc 0 "$bin/articula" phantom -o "$p" --spacing 1.2,1.2,3 -q --force
slices=$(find "$p/dicom" -name 'slice_*.dcm' | wc -l)
expect_rc 0 "$bin/articula" phantom -o "$p" --spacing 1.2,1.2,1.5 -q --force
[ "$(find "$p/dicom" -type f | wc -l)" -gt "$slices" ] || fail "the thinner slices' series: $(find "$p/dicom" -type f | wc -l) files"
expect_rc 0 "$bin/articula" phantom -o "$p" --spacing 1.2,1.2,3 -q --force
[ "$(find "$p/dicom" -type f | wc -l)" -eq "$slices" ] || fail "the thicker slices' series kept the earlier slices"
expect_rc 0 "$bin/articula" phantom -o "$p" --spacing 1.2,1.2,1.5 -q --force
echo "x" > "$tmp/a-file"
expect_rc 2 "$bin/articula" phantom -o "$tmp/a-file" -q
grep -q "is a file: expected a folder" "$tmp/err" || fail "phantom -o FILE: $(cat "$tmp/err")"

# run: a report.html of the user's in the output folder is refused by name
# before any stage; with --force it is replaced.
u="$tmp/u"
mkdir -p "$u"
echo "<p>the user's page</p>" > "$u/report.html"
expect_rc 2 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$u" -q
grep -q "refusing to overwrite .*report.html, which articula run did not write" "$tmp/err" ||
  fail "run: report.html not named: $(cat "$tmp/err")"
[ "$(ls -A "$u")" = "report.html" ] || fail "run wrote before refusing: $(ls -A "$u")"
expect_rc 2 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$tmp/a-file" -q
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
expect_rc 0 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$r" -q
[ ! -e "$r/.articula-tmp-$dead-points.ply" ] || fail "run left its own stale temporary"
for kept in .tmp-4000000-draft.txt .articula-tmp-99999999999999999999-x "drafts/.articula-tmp-$dead-draft.txt"; do
  [ -e "$r/$kept" ] || fail "run's clean-up deleted the user's $kept"
done
# A second run replaces what the first wrote without --force.
touch "$p/phantom.nii.gz"
expect_rc 0 "$bin/articula" run -i "$p/phantom.nii.gz" -o "$r" -q
# batch: a study.csv of the user's in the study folder is refused by name
# before any subject runs; a batch's own tables are replaced by its rerun.
b="$tmp/b"
mkdir -p "$b"
echo "subject,mine" > "$b/study.csv"
printf 'subject,input,joint,side\ns1,%s,hip,right\n' "$p/phantom.nii.gz" > "$tmp/manifest.csv"
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
echo "user files: ok"
