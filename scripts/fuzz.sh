#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, docs/fuzzing.md) in ./build-fuzz and
# runs each for SECONDS_PER_TARGET (default 60) on a copy of its seed corpus
# in build-fuzz/fuzz-run/<target>/ (the repository is never written to).
# Prints each target's executions; exits non-zero on any crash, sanitizer
# report, leak, timeout or out-of-memory that its input repeats, naming the
# reproducer file and printing the end of the log.
#
#   bash scripts/fuzz.sh                 # every target, 60 s each
#   bash scripts/fuzz.sh 600 fuzz_ply    # one target, 10 minutes
#   ARTICULA_FUZZ_ARGS="-jobs=2 -workers=2" bash scripts/fuzz.sh 60   # extra libFuzzer flags
set -euo pipefail
cd "$(dirname "$0")/.."
SOURCE=$PWD
SECONDS_PER_TARGET=${1:-60}
shift || true
BUILD_DIR=${ARTICULA_FUZZ_BUILD_DIR:-build-fuzz}
case $SECONDS_PER_TARGET in '' | *[!0-9]*)
  echo "usage: $0 [SECONDS_PER_TARGET] [TARGET...]" >&2
  exit 2
  ;;
esac

CC=${CC:-clang} CXX=${CXX:-clang++} cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DARTICULA_FUZZ=ON \
  -DARTICULA_BUILD_TESTS=OFF -DARTICULA_BUILD_BENCH=OFF > "$BUILD_DIR.configure.log" 2>&1 ||
  { cat "$BUILD_DIR.configure.log" >&2; exit 1; }
rm -f "$BUILD_DIR.configure.log"
cmake --build "$BUILD_DIR" --target fuzz_all -j"${ARTICULA_FUZZ_BUILD_JOBS:-2}"

if [ $# -gt 0 ]; then
  targets=("$@")
else
  targets=()
  for dir in fuzz/corpus/*/; do targets+=("$(basename "$dir")"); done
fi

# Leaks inside ITK's and VTK's own caches are theirs (fuzz/lsan.supp names the libraries).
export LSAN_OPTIONS="suppressions=$SOURCE/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"

failed=0
printf '%-20s %12s %8s %10s  %s\n' target executions seconds corpus result
for target in "${targets[@]}"; do
  bin="$BUILD_DIR/bin/$target"
  [ -x "$bin" ] || { echo "$target: no executable $bin" >&2; failed=1; continue; }
  run="$BUILD_DIR/fuzz-run/$target"
  rm -rf "$run"
  mkdir -p "$run/corpus"
  cp fuzz/corpus/"$target"/* "$run/corpus/"
  dict=()
  [ -f "fuzz/$target.dict" ] && dict=(-dict="$SOURCE/fuzz/$target.dict")
  start=$(date +%s)
  set +e
  # shellcheck disable=SC2086 # ARTICULA_FUZZ_ARGS is a list of flags
  "$bin" -max_total_time="$SECONDS_PER_TARGET" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    -artifact_prefix="$run/" "${dict[@]}" ${ARTICULA_FUZZ_ARGS:-} "$run/corpus" > "$run/log" 2>&1
  rc=$?
  set -e
  elapsed=$(($(date +%s) - start))
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$run/log" | tail -1)
  [ -n "$executions" ] || executions=$(grep -o '^#[0-9]*' "$run/log" | tail -1 | tr -d '#')
  corpus=$(find "$run/corpus" -type f | wc -l)
  if [ "$rc" -eq 0 ]; then
    printf '%-20s %12s %8s %10s  %s\n' "$target" "${executions:-?}" "$elapsed" "$corpus" ok
  else
    reproducer=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$run/log" | tail -1)
    kind=$(grep -m1 -o 'ERROR: [A-Za-z]*Sanitizer: [a-z-]*\|ERROR: libFuzzer: [a-z-]*\|runtime error\|fuzz: exception[^:]*' "$run/log" || true)
    # As OSS-Fuzz does, a crash its own input does not repeat in a fresh
    # process (three tries) is reported as unreproducible and does not fail
    # the run: what it printed is kept below for a look.
    verdict="FAILED (exit $rc)"
    if [ -n "$reproducer" ] && [ -f "$reproducer" ] &&
      "$bin" -runs=3 -rss_limit_mb=2048 -timeout=10 "$reproducer" > "$run/rerun.log" 2>&1; then
      verdict="unreproducible crash (exit $rc; its input passes 3 reruns)"
    else
      failed=1
    fi
    printf '%-20s %12s %8s %10s  %s\n' "$target" "${executions:-?}" "$elapsed" "$corpus" "$verdict"
    echo "  ${kind:-see the log}; log: $run/log" >&2
    echo "  reproducer: ${reproducer:-none written}  (rerun: $bin ${reproducer:-})" >&2
    # The log's end (the signal, the assertion or the stack) outlives the
    # run folder only here, in the CI record.
    grep -v '^#[0-9]\|^INFO:\|^articula: ' "$run/log" | tail -n 40 | sed 's/^/  | /' >&2
  fi
done
exit "$failed"
