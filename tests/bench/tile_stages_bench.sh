#!/usr/bin/env bash
# The stages that run block by block (issue 36, item 3) on fractal relief at
# 1 m larger than one block: drift import of the VRT of tiled GeoTIFFs that
# tests/bench/make_fractal_dem.py makes, then drift snow cover of the imported
# DEM, and (when asked) drift snow fall with its occlusion block by block and
# the one-step stabilisation, each once under /usr/bin/time -v. Prints
# wall-clock and CPU seconds and the peak resident memory of each; the figures
# go in docs/terrain.md, docs/snow.md and docs/snowfall.md.
#
#   tests/bench/tile_stages_bench.sh BUILD_DIR DATA_DIR [SIZE...]   (default 16384)
#
# DRIFT=path overrides BUILD_DIR/pipeline/drift; BLOCK (default: the stages'
# own, 2048) sets --block; COVER_ARGS (default: the paper's region and probe
# radius in cells, "--region-cells 3 --radius-cells 5.5", halo 18) the
# descriptor's options ("" for the metric defaults, which widen the region to
# 150 cells on a 1 m DEM: halo 753, so give BLOCK=4096). The data stays in
# DATA_DIR for reruns (16384^2: 16 tiles, ~0.6 GB). STAGES (default
# "import cover") names the stages to time, any of import, cover, snowfall (a
# stage that needs the imported DEM imports it untimed if it is missing);
# snowfall takes MAPS (default 4) for --maps, STABILISE (default direct) for
# --stabilise and --block BLOCK (default 4096).
set -euo pipefail
build=${1:?usage: tile_stages_bench.sh BUILD_DIR DATA_DIR [SIZE...]}
data=${2:?usage: tile_stages_bench.sh BUILD_DIR DATA_DIR [SIZE...]}
shift 2
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(16384)
drift=$(realpath "${DRIFT:-$build/pipeline/drift}")
here=$(cd "$(dirname "$0")" && pwd)
block=()
[ -z "${BLOCK:-}" ] || block=(--block "$BLOCK")
read -r -a cover_args <<< "${COVER_ARGS---region-cells 3 --radius-cells 5.5}"
mkdir -p "$data"
cd "$data"
# One line of figures from a /usr/bin/time -v log.
figures() {
  awk -F': ' '/Elapsed/ {wall=$2} /User time/ {u=$2} /System time/ {s=$2}
    /Maximum resident/ {peak=$2}
    END {printf "%12s %10.1f %10.1f\n", wall, u + s, peak / 1024}' "$1"
}
printf '%-7s %-12s %12s %10s %10s\n' size stage wall cpu_s peak_MiB
stages=" ${STAGES:-import cover} "
for n in "${sizes[@]}"; do
  [ -f "fractal_$n.vrt" ] ||
    /usr/bin/python3 "$here/make_fractal_dem.py" "$n" . --tile $((n < 4096 ? n : 4096)) >&2
  if [[ $stages == *" import "* ]]; then
    /usr/bin/time -v "$drift" import "fractal_$n.vrt" -o "imported_$n.tif" "${block[@]}" \
      > "import_$n.log" 2>&1
    printf '%-7s %-12s %s\n' "$n" import "$(figures "import_$n.log")"
  elif [ ! -f "imported_$n.tif" ]; then
    "$drift" import "fractal_$n.vrt" -o "imported_$n.tif" "${block[@]}" > "import_$n.log" 2>&1
  fi
  if [[ $stages == *" cover "* ]]; then
    /usr/bin/time -v "$drift" snow cover "imported_$n.tif" "${cover_args[@]}" "${block[@]}" \
      -o "cover_$n.tif" --descriptor "t_$n.tif" --accessibility "tsa_$n.tif" > "cover_$n.log" 2>&1
    printf '%-7s %-12s %s\n' "$n" "snow cover" "$(figures "cover_$n.log")"
  fi
  if [[ $stages == *" snowfall "* ]]; then
    /usr/bin/time -v "$drift" snow fall "imported_$n.tif" --block "${BLOCK:-4096}" \
      --maps "${MAPS:-4}" --stabilise "${STABILISE:-direct}" --direction 300,55 --spread 8 \
      -o "snowfall_$n.tif" > "snowfall_$n.log" 2>&1
    printf '%-7s %-12s %s\n' "$n" "snow fall" "$(figures "snowfall_$n.log")"
  fi
done
