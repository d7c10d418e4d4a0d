#!/usr/bin/env bash
# Installs every Debian 12 package articula builds, tests and benchmarks with.
# Non-interactive and idempotent: packages already present are skipped, so a
# second run makes no network request.
set -euo pipefail

PACKAGES=(
  build-essential cmake git pkg-config libssl-dev
  libinsighttoolkit5-dev libvtk9-dev libcgal-dev libeigen3-dev
  libnlopt-cxx-dev libcli11-dev nlohmann-json3-dev zlib1g-dev
  libgtest-dev libbenchmark-dev
  # measured peers (contact benchmarks) and the multibody engine
  libsimbody-dev libfcl-dev libccd-dev libbullet-dev
  # the reports' inlined 3-D view; the browser and schema checks of the tests
  libjs-three chromium python3-jsonschema
  # the independent hip phantoms of bench/independent_phantoms.sh
  python3-numpy python3-scipy
  # studies that outgrow one machine (pipelines/Snakefile)
  snakemake
  # fuzzing the readers (scripts/fuzz.sh): Clang and its libFuzzer runtime
  clang libclang-rt-14-dev
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install-deps: done"
