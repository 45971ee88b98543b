#!/usr/bin/env bash
# Snowfall on fractal relief at 1 m tile by tile (issue 36, items 3 and 5):
# makes the data (tests/bench/make_fractal_dem.py: a VRT of tiled GeoTIFFs
# with overviews), imports it (drift import, block by block), then runs
# drift snow fall with its occlusion block by block (--block) and the
# one-step stabilisation, each under /usr/bin/time -v. Prints wall-clock and
# CPU seconds and the peak resident memory of each; the figures go in
# docs/snowfall.md.
#
#   scripts/snowfall_tile_bench.sh BUILD_DIR DATA_DIR [SIZE...]   (default 16384)
#
# DRIFT=path overrides BUILD_DIR/pipeline/drift; BLOCK (default 4096) sets
# snow fall's --block; MAPS (default 4) its --maps; STABILISE (default
# direct) its --stabilise. The data stays in DATA_DIR for reruns (16384^2:
# 16 tiles, ~0.6 GB; the depth raster ~1 GB).
set -euo pipefail
build=${1:?usage: snowfall_tile_bench.sh BUILD_DIR DATA_DIR [SIZE...]}
data=${2:?usage: snowfall_tile_bench.sh BUILD_DIR DATA_DIR [SIZE...]}
shift 2
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(16384)
drift=$(realpath "${DRIFT:-$build/pipeline/drift}")
here=$(cd "$(dirname "$0")/.." && pwd)/tests/bench
mkdir -p "$data"
cd "$data"
# One line of figures from a /usr/bin/time -v log.
figures() {
  awk -F': ' '/Elapsed/ {wall=$2} /User time/ {u=$2} /System time/ {s=$2}
    /Maximum resident/ {peak=$2}
    END {printf "%12s %10.1f %10.1f\n", wall, u + s, peak / 1024}' "$1"
}
printf '%-7s %-12s %12s %10s %10s\n' size stage wall cpu_s peak_MiB
for n in "${sizes[@]}"; do
  [ -f "fractal_$n.vrt" ] ||
    /usr/bin/python3 "$here/make_fractal_dem.py" "$n" . --tile $((n < 4096 ? n : 4096)) >&2
  if [ ! -f "imported_$n.tif" ]; then
    /usr/bin/time -v "$drift" import "fractal_$n.vrt" -o "imported_$n.tif" > "import_$n.log" 2>&1
    printf '%-7s %-12s %s\n' "$n" import "$(figures "import_$n.log")"
  fi
  /usr/bin/time -v "$drift" snow fall "imported_$n.tif" --block "${BLOCK:-4096}" \
    --maps "${MAPS:-4}" --stabilise "${STABILISE:-direct}" --direction 300,55 --spread 8 \
    -o "snowfall_$n.tif" > "snowfall_$n.log" 2>&1
  printf '%-7s %-12s %s\n' "$n" "snow fall" "$(figures "snowfall_$n.log")"
done
