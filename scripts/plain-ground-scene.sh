#!/usr/bin/env bash
# Prints the plain-ground variant of data/scenes/default.toml as a scene file:
# its sun, sky and default camera; grey Lambertian ground (albedo 0.3); the
# DEM alone, with no ground beyond it (the Cycles mesh has none). Shared by
# scripts/compare-cycles.sh and tests/bench/render_bench_convergence.sh.
#   scripts/plain-ground-scene.sh DEM [WIDTH HEIGHT] > plain.toml
set -euo pipefail
if [ $# -ne 1 ] && [ $# -ne 3 ]; then
  echo "usage: $0 DEM [WIDTH HEIGHT]" >&2
  exit 2
fi
cat <<SCENE
[terrain]
raster = "$1"
color = [0.3, 0.3, 0.3]
roughness = 0
surround_reach = 0
[sun]
azimuth = 110
elevation = 28
irradiance = 3.0
[sky]
visibility = 120
[render]
max_depth = 4
SCENE
if [ $# -eq 3 ]; then
  printf 'width = %s\nheight = %s\n' "$2" "$3"
fi
