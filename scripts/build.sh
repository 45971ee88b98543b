#!/usr/bin/env bash
# Configures and builds Driftscape (Release, assertions on) into build/,
# through ccache when it is installed (scripts/ccache-env.sh):
#   scripts/build.sh [TARGET...]   (default: everything; setup.sh asks for drift alone)
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${DRIFT_JOBS:-$(nproc)}"
# shellcheck source=scripts/ccache-env.sh
source scripts/ccache-env.sh "$PWD"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${drift_launcher[@]}" >/dev/null
targets=()
for target in "$@"; do targets+=(--target "$target"); done
cmake --build build -j "$jobs" "${targets[@]}"
