#!/usr/bin/env bash
# Installs exactly the Debian 12 packages Driftscape builds, tests and runs with.
# Does nothing (and needs no network) when they are all present already.
#   scripts/install-deps.sh [--lint]
set -euo pipefail

packages=(
  build-essential cmake pkg-config make ccache
  libembree-dev libeigen3-dev libtbb-dev
  libopenimageio-dev libopenexr-dev
  libgdal-dev gdal-bin python3-gdal python3-numpy
  parallel
  libosmesa6-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev libtomlplusplus-dev libtinyobjloader-dev libassimp-dev
  libopenvdb-dev libboost-iostreams-dev
  fonts-dejavu-core
)
# --lint: also what scripts/lint.sh runs (not in CI yet: docs/testing.md says why).
if [ "${1:-}" = "--lint" ]; then
  packages+=(python3 clang-format clang-tidy cppcheck)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
