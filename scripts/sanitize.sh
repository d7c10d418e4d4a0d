#!/usr/bin/env bash
# The sanitizer tier (docs/testing.md): builds the library, the programs and
# the tests (not the benchmarks) with AddressSanitizer +
# UndefinedBehaviorSanitizer in build-asan, then runs every test there but
# those of full-size phantoms (label full-size). Any sanitizer report fails
# its test. -O1 with line tables only: about half the build time of
# RelWithDebInfo, still with file:line in every report. GCC, not the Clang
# build of the fuzz targets: the tests ran 2.7x longer under Clang with the
# fuzzers' coverage instrumentation, more than a second build costs.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${ARTICULA_ASAN_BUILD_DIR:-build-asan}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
  -DARTICULA_SANITIZE=ON -DARTICULA_BUILD_TESTS=ON -DARTICULA_BUILD_BENCH=OFF
cmake --build "$BUILD_DIR" -j"$(nproc)"
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:detect_stack_use_after_return=0:strict_string_checks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)" --timeout 900 --label-exclude "full-size|scheduler"
