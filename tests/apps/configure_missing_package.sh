#!/usr/bin/env bash
# Configure fails early, naming the Debian package of a missing dependency.
# (CMAKE_DISABLE_FIND_PACKAGE_<name> makes CMake behave as if it were absent.)
set -euo pipefail
src=${ARTICULA_SOURCE:?}
tmp=${ARTICULA_TMP:?}
rm -rf "$tmp" && mkdir -p "$tmp"
set +e
cmake -S "$src" -B "$tmp/build" -DCMAKE_DISABLE_FIND_PACKAGE_CLI11=TRUE \
  -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=TRUE > "$tmp/log" 2>&1
rc=$?
set -e
[ "$rc" -ne 0 ] || { echo "FAIL: configure succeeded without CLI11" >&2; exit 1; }
grep -q "missing Debian packages: libcli11-dev nlohmann-json3-dev" "$tmp/log" || {
  cat "$tmp/log" >&2
  echo "FAIL: message does not name the packages" >&2
  exit 1
}
grep -q "scripts/install-deps.sh" "$tmp/log" || { echo "FAIL: message does not say how to install" >&2; exit 1; }
echo "configure_missing_package: ok"
