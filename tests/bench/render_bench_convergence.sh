#!/usr/bin/env bash
# How fast the renderer's noise falls: relMSE at 4, 16, 64 and 256 spp and
# the slopes of log relMSE over log spp, for the default scene and for a flat
# grey plane under the sun and the physical sky (docs/rendering.md,
# "Sampling"). Not a test: it takes minutes.
#
#   tests/bench/render_bench_convergence.sh [DRIFT]
#
# The error is measured without a reference: two renders of each count with
# seeds 1 and 2 are independent and unbiased, so the expected relMSE between
# them is twice each one's relMSE against the converged image; half of it is
# what a reference of infinitely many samples would give, where a finite
# reference adds its own noise (a 4096-spp one about a sixth of a 256-spp
# render's with independent samples) and flattens the slope.
#
# With REF_SPP (e.g. 4096) set, each count's render of seed 1 is measured
# against one reference of REF_SPP samples and seed 2 instead (the issue's
# measure; the reference's own noise adds to every figure and flattens the
# slope a little at 256 spp).
#
# DRIFT (default build/pipeline/drift) renders into WORK (default
# /tmp/drift_convergence); SIZE (320x180), THREADS (0: all) and SCENES
# ("default flat plain") may be set. "plain" is the default DEM's
# plain-ground frame of scripts/compare-cycles.sh (grey Lambertian ground,
# albedo 0.3, the DEM alone). The default scene needs out/yarigatake_utm.tif
# (make -C data/scenes default).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
drift="$(realpath "${1:-$root/build/pipeline/drift}")"
work="${WORK:-/tmp/drift_convergence}"
size="${SIZE:-320x180}"
threads="${THREADS:-0}"
mkdir -p "$work"

# The flat plane: 2.56 km of level ground at 1000 m (10 m cells, UTM 53N),
# albedo 0.3, seen from 300 m up at 45 degrees down (no sky in the frame).
if [ ! -f "$work/flat.tif" ]; then
  gdal_create -q -of GTiff -outsize 256 256 -bands 1 -ot Float32 -burn 1000 \
    -a_srs EPSG:32653 -a_ullr 500000 4000000 502560 3997440 "$work/flat.tif"
fi
cat > "$work/flat.toml" <<EOF
[terrain]
raster = "$work/flat.tif"
color = [0.3, 0.3, 0.3]
[sun]
azimuth = 135
elevation = 35
[camera]
from = [501280, 3998420, 1300]
to = [501280, 3998720, 1000]
[render]
seed = 1
EOF

# The plain-ground variant of the default scene (scripts/compare-cycles.sh).
"$root/scripts/plain-ground-scene.sh" "$root/out/yarigatake_utm.tif" > "$work/plain.toml"

scene_file() {
  case "$1" in
    default) echo "$root/data/scenes/default.toml --terrain $root/out/yarigatake_utm.tif" ;;
    flat) echo "$work/flat.toml" ;;
    plain) echo "$work/plain.toml" ;;
  esac
}

ref_spp="${REF_SPP:-0}"
seeds="1 2"
[ "$ref_spp" -gt 0 ] && seeds="1"

for scene in ${SCENES:-default flat plain}; do
  logs=()
  if [ "$ref_spp" -gt 0 ] && [ ! -f "$work/${scene}_ref${ref_spp}.exr" ]; then
    # shellcheck disable=SC2046
    "$drift" render $(scene_file "$scene") --size "$size" --spp "$ref_spp" --seed 2 \
      --threads "$threads" -o "$work/${scene}_ref${ref_spp}.exr" >/dev/null
  fi
  for spp in 4 16 64 256; do
    cpu=0
    for seed in $seeds; do
      # shellcheck disable=SC2046
      /usr/bin/time -f "%U %S" -o "$work/time" "$drift" render $(scene_file "$scene") \
        --size "$size" --spp "$spp" --seed "$seed" --threads "$threads" \
        -o "$work/${scene}_${spp}_${seed}.exr" >/dev/null
      cpu=$(awk -v c="$cpu" '{print c + $1 + $2}' "$work/time")
    done
    if [ "$ref_spp" -gt 0 ]; then
      rel=$({ "$drift" compare "$work/${scene}_${spp}_1.exr" "$work/${scene}_ref${ref_spp}.exr" \
        --metric relmse || true; } | awk '/^relmse:/ {print $2}')
      runs=1
    else
      pair=$({ "$drift" compare "$work/${scene}_${spp}_1.exr" "$work/${scene}_${spp}_2.exr" \
        --metric relmse || true; } | awk '/^relmse:/ {print $2}')
      rel=$(awk -v p="$pair" 'BEGIN {print p / 2}')
      runs=2
    fi
    printf '%s %4d spp: relMSE %.4g  (%.1f s CPU a render)\n' "$scene" "$spp" "$rel" \
      "$(awk -v c="$cpu" -v n="$runs" 'BEGIN {print c / n}')"
    logs+=("$spp $rel")
  done
  # Least-squares slopes of log relMSE against log spp: 4-64 and 4-256.
  printf '%s\n' "${logs[@]}" | awk -v scene="$scene" '
    function fit(n,   i, sx, sy, sxx, sxy) {
      for (i = 1; i <= n; ++i) { sx += x[i]; sy += y[i]; sxx += x[i] * x[i]; sxy += x[i] * y[i] }
      return (n * sxy - sx * sy) / (n * sxx - sx * sx)
    }
    { x[NR] = log($1); y[NR] = log($2) }
    END { printf "%s slopes: 4-64 spp %.2f, 4-256 spp %.2f\n", scene, fit(3), fit(4) }'
done
