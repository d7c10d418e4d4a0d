#!/usr/bin/env bash
# Remakes the figures of docs/user-guide.md (docs/images/*.svg) with the tool
# itself, with fixed seeds. Builds nothing: give it the build's bin folder.
#
#   scripts/make-doc-figures.sh build/bin [WORK_DIR]
#
# WORK_DIR (default: a new temporary folder) keeps the demo and study outputs.
set -euo pipefail
bin=${1:?usage: scripts/make-doc-figures.sh BUILD/bin [WORK_DIR]}
bin=$(cd "$bin" && pwd)
[ -x "$bin/articula" ] || { echo "no articula executable in $bin" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
work=${2:-$(mktemp -d -t articula-doc-figures.XXXXXX)}
mkdir -p "$work"
work=$(cd "$work" && pwd)
images=$root/docs/images
mkdir -p "$images"

# One subject: the demo (a superovoid femoral head in a synthetic hip CT).
nice "$bin/articula" demo -o "$work/demo" --model superovoid --seed 7 --force --quiet > "$work/demo.txt"
cp "$work/demo/run/errors/histogram.svg" "$images/demo-histogram.svg"
cp "$work/demo/run/errors/error_map.svg" "$images/demo-error-map.svg"

# A study of three phantoms whose heads have different true shapes (manifest
# as in tests/apps/study.sh).
printf 'subject,input,joint,side\n' > "$work/study.csv"
for subject in "s01 sphere 3" "s02 ellipsoid 5" "s03 superovoid 11"; do
  read -r id model seed <<< "$subject"
  nice "$bin/articula" phantom -o "$work/data/$id" --model "$model" --seed "$seed" --no-dicom --force --quiet
  printf '%s,data/%s/phantom.nii.gz,hip,right\n' "$id" "$id" >> "$work/study.csv"
done
nice "$bin/articula" batch "$work/study.csv" -o "$work/study" -j 1 --seed 42 --quiet
cp "$work/study/study.svg" "$images/study.svg"

for f in demo-histogram.svg demo-error-map.svg study.svg; do
  size=$(stat -c %s "$images/$f")
  [ "$size" -le 204800 ] || { echo "$images/$f is $size bytes (more than 200 KB)" >&2; exit 1; }
  echo "$images/$f: $size bytes"
done
echo "outputs kept in $work"
