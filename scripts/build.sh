#!/usr/bin/env bash
# Configures and builds Driftscape (Release, assertions on) into build/:
#   scripts/build.sh [TARGET...]   (default: everything; setup.sh asks for drift alone)
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${DRIFT_JOBS:-$(nproc)}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
targets=()
for target in "$@"; do targets+=(--target "$target"); done
cmake --build build -j "$jobs" "${targets[@]}"
