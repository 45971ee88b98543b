#!/usr/bin/env bash
# Bytes a DEM cell in core when drift render draws fractal relief at 1 m
# (issue 36): makes the data (tests/bench/make_fractal_dem.py, a VRT of tiled,
# overviewed GeoTIFFs), renders each size once with /usr/bin/time -v and
# prints peak resident memory, bytes a cell, the time to read the DEM (and
# start) and the time drift render reports (Embree scene set-up and the
# frame; BM_TerrainSceneBuild in render_bench times the set-up alone).
#
#   tests/bench/render_scale_bench.sh BUILD_DIR DATA_DIR [SIZE...]   (default 4096 16384)
#
# DRIFT=path overrides BUILD_DIR/pipeline/drift (e.g. an older binary to
# compare); RENDER_SIZE (320x180) and SPP (4) set the frame; HEIGHT_BITS=16
# holds the DEM in core as 16-bit heights (drift render --height-bits 16);
# FAST=1 makes the data with make_fractal_dem.py --fast at every size
# (seamless; larger sizes link the smaller's tiles) instead of mosaics; MEMORY_BUDGET
# (e.g. 2G) renders out of core (drift render --memory-budget) and prints the
# page cache's line (with the scene set-up time: the opening scan, the tree
# and Embree's BVH). The data stays in DATA_DIR for reruns (16384^2: 16
# tiles, ~1.1 GB; made in ~5 min of CPU); sizes above 16384 are VRT mosaics
# repeating its tiles (tests/bench/make_mosaic_vrt.py).
set -euo pipefail
build=${1:?usage: render_scale_bench.sh BUILD_DIR DATA_DIR [SIZE...]}
data=${2:?usage: render_scale_bench.sh BUILD_DIR DATA_DIR [SIZE...]}
shift 2
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(4096 16384)
drift=${DRIFT:-$build/pipeline/drift}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$data"
printf '%-7s %12s %10s %10s %16s %8s\n' size peak_MiB B/cell read_s scene+render_s cpu_s
for n in "${sizes[@]}"; do
  if [ ! -f "$data/fractal_$n.vrt" ]; then
    if [ -n "${FAST:-}" ]; then  # seamless, ~5x less CPU a tile (8 s of CPU a 4096^2 tile)
      /usr/bin/python3 "$here/make_fractal_dem.py" "$n" "$data" --tile $((n < 4096 ? n : 4096)) \
        --fast --jobs 2 >&2
    elif [ "$n" -gt 16384 ]; then  # made tile by tile, 32768^2 takes ~7 min of CPU, 65536^2 ~30 min:
      [ -f "$data/fractal_16384.vrt" ] ||  # repeat the 16384^2 tiles instead
        /usr/bin/python3 "$here/make_fractal_dem.py" 16384 "$data" --tile 4096 >&2
      /usr/bin/python3 "$here/make_mosaic_vrt.py" "$n" "$data" --from 16384 >&2
    else
      /usr/bin/python3 "$here/make_fractal_dem.py" "$n" "$data" --tile $((n < 4096 ? n : 4096)) >&2
    fi
  fi
  scene="$data/scale_$n.toml"
  cat > "$scene" <<EOF
[terrain]
raster = "fractal_$n.vrt"
[sun]
azimuth = 135
elevation = 30
[render]
spp = ${SPP:-4}
EOF
  log="$data/scale_$n${HEIGHT_BITS:+_$HEIGHT_BITS}.log"
  /usr/bin/time -v "$drift" render "$scene" --size "${RENDER_SIZE:-320x180}" \
    -o "$data/scale_$n${HEIGHT_BITS:+_$HEIGHT_BITS}.png" --exposure 0 \
    ${MEMORY_BUDGET:+--memory-budget "$MEMORY_BUDGET"} ${HEIGHT_BITS:+--height-bits "$HEIGHT_BITS"} \
    > "$log" 2>&1
  peak_kib=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$log")
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$log")
  render_s=$(sed -n 's/^rendered .* in \([0-9.]*\) s.*/\1/p' "$log")
  cpu_s=$(awk -F': ' '/User time|System time/ { s += $2 } END { print s }' "$log")
  total_s=$(echo "$wall" | awk -F: '{ s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; print s }')
  awk -v n="$n" -v kib="$peak_kib" -v r="$render_s" -v t="$total_s" -v c="$cpu_s" 'BEGIN {
    printf "%-7s %12.0f %10.2f %10.1f %16.1f %8.1f\n", n "^2", kib / 1024, kib * 1024 / (n * n), t - r, r, c }'
  grep '^terrain cache:' "$log" || true
done
