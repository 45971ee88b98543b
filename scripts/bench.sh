#!/usr/bin/env bash
# Runs every stage's benchmark (throughput and peak memory); not part of the tests.
# The render benchmark needs the imported default DEM: it is made first.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
make -C data/scenes DRIFT="$PWD/build/pipeline/drift" OUT="$PWD/out" "$PWD/out/yarigatake_utm.tif"
for b in build/tests/bench/*_bench; do
  echo "== $b"
  /usr/bin/time -v "$b" 2>&1 | grep -vE "^\s+(Average|Exit|Socket|Signals|Swaps|File system|Page size|Voluntary|Involuntary|Minor|Major|Percent|System time|User time)"
done
