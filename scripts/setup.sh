#!/usr/bin/env bash
# One command on a fresh Debian 12 machine: installs the packages, builds, and
# renders the default scene (Yarigatake, from the real DEM in data/) into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
make -C data/scenes DRIFT="$PWD/build/pipeline/drift" OUT="$PWD/out" default
echo "setup: rendered $(ls out/default.* 2>/dev/null | tr '\n' ' ')"
