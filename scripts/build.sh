#!/usr/bin/env bash
# Configures and builds articula in ./build (Release). Extra arguments go to
# the configure step, e.g.: bash scripts/build.sh -DARTICULA_SANITIZE=ON
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${ARTICULA_BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=${CMAKE_BUILD_TYPE:-Release} "$@"
cmake --build "$BUILD_DIR" -j"$(nproc)"
