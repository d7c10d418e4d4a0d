#!/usr/bin/env bash
# Installs the Debian 12 packages articula needs. Non-interactive and
# idempotent: packages already present are skipped, so a second run makes no
# network request.
#
#   bash scripts/install-deps.sh         # building and running articula
#   bash scripts/install-deps.sh --all   # and its tests, benchmarks, fuzzing,
#                                        # browser checks and Snakemake
set -euo pipefail

# What `articula` itself builds and runs with.
PACKAGES=(
  build-essential cmake git pkg-config libssl-dev
  libinsighttoolkit5-dev libvtk9-dev libcgal-dev libeigen3-dev
  libnlopt-cxx-dev libcli11-dev nlohmann-json3-dev zlib1g-dev
  # the distributions of the model selection's tests (Boost.Math, headers)
  libboost-dev
  # the multibody engine of lib/dynamics
  libsimbody-dev
  # the reports' 3-D view, inlined at build time
  libjs-three
)
# What only the tests, benchmarks, fuzzing and cluster runs need.
DEVELOPMENT_PACKAGES=(
  libgtest-dev libbenchmark-dev
  # measured contact peers (bench/)
  libfcl-dev libccd-dev libbullet-dev
  # the browser and schema checks of the tests
  chromium python3-jsonschema
  # the independent hip phantoms of the tests and bench/
  python3-numpy python3-scipy
  # studies that outgrow one machine (pipelines/Snakefile), and the
  # single-node Slurm cluster its Slurm profile is tested on (tests/apps/slurm.sh)
  snakemake slurmctld slurmd slurm-client munge
  # the sanitizer tier and fuzzing (scripts/sanitize.sh, scripts/fuzz.sh):
  # Clang and its libFuzzer runtime
  clang libclang-rt-14-dev
  # a compiler cache, so that CI's clean clones rebuild only what changed
  ccache
)

case "${1:-}" in
  "") ;;
  --all) PACKAGES+=("${DEVELOPMENT_PACKAGES[@]}") ;;
  *) echo "usage: $0 [--all]" >&2; exit 2 ;;
esac

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
