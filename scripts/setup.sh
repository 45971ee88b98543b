#!/usr/bin/env bash
# One command on a fresh Debian 12 machine: installs the packages, builds the
# drift program alone (not the tests and benchmarks: scripts/test.sh builds
# those) and renders the default scene (Yarigatake, from the real DEM in
# data/) into out/, so the first image comes as soon as it can.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
./scripts/install-deps.sh
./scripts/build.sh drift
make -C data/scenes DRIFT="$PWD/build/pipeline/drift" OUT="$PWD/out" default
echo "setup: rendered $(ls out/default.* 2>/dev/null | tr '\n' ' ')in $((SECONDS - start)) s"
echo "setup: ./scripts/test.sh builds and runs the tests"
