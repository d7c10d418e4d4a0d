#!/usr/bin/env bash
# Reports: the report stage's wall time (median of 5, `articula report
# --force` with the CT read for its slices) and report.html's size, on the
# demo phantom and, when ../shared/data is there, the thorax series' right
# shoulder; then study.html's size for a batch of N phantom subjects
# (default 50; seeds 1..N, both sides). Targets: report.html <= 5 MB written
# in <= 1 s; study.html of 50 subjects <= 10 MB.
#   bash bench/reports.sh [build/bin] [scratch dir] [N]
set -euo pipefail
bin=$(cd "${1:-build/bin}" && pwd)
work=${2:-$(mktemp -d)}
n=${3:-50}
shared=$(cd "$(dirname "$0")/.." && pwd)/../shared/data
mkdir -p "$work"

median_report_seconds() {  # folder, then report options
  local folder=$1; shift
  for _ in 1 2 3 4 5; do
    /usr/bin/time -f "%e" -o "$work/time.txt" "$bin/articula" report -i "$folder" "$@" --force --quiet
    cat "$work/time.txt"
  done | sort -n | sed -n 3p
}

"$bin/articula" demo -o "$work/demo" --quiet > /dev/null
echo "demo phantom: report $(median_report_seconds "$work/demo/run" --ct "$work/demo/phantom/dicom") s," \
  "report.html $(stat -c %s "$work/demo/run/report.html") bytes"
if [ -d "$shared/ct/thorax-shoulders-dicom" ]; then
  "$bin/articula" run -i "$shared/ct/thorax-shoulders-dicom" -o "$work/thorax" --joint shoulder --side right --quiet
  echo "thorax right shoulder: report $(median_report_seconds "$work/thorax" --ct "$shared/ct/thorax-shoulders-dicom" \
    --joint shoulder --side right) s, report.html $(stat -c %s "$work/thorax/report.html") bytes"
fi

echo "subject,input,joint,side" > "$work/study.csv"
for i in $(seq 1 "$n"); do
  side=$([ $((i % 2)) -eq 0 ] && echo left || echo right)
  [ -e "$work/data/s$i/phantom.nii.gz" ] ||
    "$bin/articula" phantom -o "$work/data/s$i" --seed "$i" --side "$side" --no-dicom --quiet
  echo "s$i,data/s$i/phantom.nii.gz,hip,$side" >> "$work/study.csv"
done
"$bin/articula" batch "$work/study.csv" -o "$work/study" -j 2 --quiet || true
sizes=$(stat -c %s "$work"/study/subjects/*/report.html | sort -n)
echo "study of $n subjects: study.html $(stat -c %s "$work/study/study.html") bytes;" \
  "report.html $(echo "$sizes" | head -1)-$(echo "$sizes" | tail -1) bytes;" \
  "$(grep -c ',ok,' "$work/study/study_status.csv") ok"
