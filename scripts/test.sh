#!/usr/bin/env bash
# Builds Driftscape and runs the whole test suite (unit, physics and golden-image tests).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
ctest --test-dir build --output-on-failure -j "${DRIFT_JOBS:-$(nproc)}" "$@"
