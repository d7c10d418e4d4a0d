#!/usr/bin/env bash
# Configures and builds articula in ./build (Release).
#
#   bash scripts/build.sh          # everything: programs, tests, benchmarks
#   bash scripts/build.sh --apps   # the articula programs only (what a run needs)
#
# Further arguments go to the configure step, e.g.
#   bash scripts/build.sh -DARTICULA_SANITIZE=ON
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${ARTICULA_BUILD_DIR:-build}
parts=(-DARTICULA_BUILD_TESTS=ON -DARTICULA_BUILD_BENCH=ON)
if [ "${1:-}" = "--apps" ]; then
  shift
  parts=(-DARTICULA_BUILD_TESTS=OFF -DARTICULA_BUILD_BENCH=OFF)
fi
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE="${CMAKE_BUILD_TYPE:-Release}" "${parts[@]}" "$@"
cmake --build "$BUILD_DIR" -j"$(nproc)"
