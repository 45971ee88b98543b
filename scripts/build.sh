#!/usr/bin/env bash
# Configures and builds Driftscape (Release, assertions on) into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${DRIFT_JOBS:-$(nproc)}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs"
