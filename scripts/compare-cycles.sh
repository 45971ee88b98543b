#!/usr/bin/env bash
# Driftscape against Blender Cycles on the default DEM's plain-ground frame
# (issue 35; docs/rendering.md, "Against Cycles"): the same camera, sun and
# grey Lambertian ground (albedo 0.3), each renderer's physical sky, 3 diffuse
# bounces, no denoiser, no adaptive sampling, no clamping, a 1-pixel box
# filter, the same size, samples and threads. A benchmark, not a test: never
# run by CTest or CI.
#
#   scripts/compare-cycles.sh [--install] BUILD_DIR [WORK_DIR]
#
# --install installs Debian's blender (3.4 on Debian 12) first. Settings by
# environment: SIZE (960x540), SPP (16), SPP_LO (4), REF_SPP (256), THREADS (2).
# Prints, for each renderer: set-up time, time per sample (from the renders
# at SPP and SPP_LO, set-up cancelled), peak memory (max RSS), relMSE at SPP
# and SPP_LO against its own REF_SPP reference of another seed (mean squared
# error over the reference's squared mean), and the time Driftscape needs to
# reach Cycles' relMSE at SPP (its own relMSE's slope between SPP_LO and SPP).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--install" ]; then
  shift
  apt-get update && apt-get install -y --no-install-recommends blender
fi
if [ $# -lt 1 ]; then
  echo "usage: scripts/compare-cycles.sh [--install] BUILD_DIR [WORK_DIR]" >&2
  exit 2
fi
BLENDER=${BLENDER:-blender}
if ! command -v "$BLENDER" >/dev/null; then
  echo "compare-cycles: error: '$BLENDER' not found; install Debian's Blender 3.4 with" \
    "'apt-get install blender' (or run with --install), or set BLENDER=/path/to/blender" >&2
  exit 1
fi
for tool in oiiotool gdal_translate gdalinfo /usr/bin/time python3; do
  command -v "$tool" >/dev/null || {
    echo "compare-cycles: error: $tool not found (scripts/install-deps.sh installs it)" >&2
    exit 1
  }
done
DRIFT=$1/pipeline/drift
[ -x "$DRIFT" ] || { echo "compare-cycles: error: no $DRIFT; build the drift target first" >&2; exit 1; }
WORK=${2:-out/compare-cycles}
SIZE=${SIZE:-960x540} SPP=${SPP:-16} SPP_LO=${SPP_LO:-4} REF_SPP=${REF_SPP:-256} THREADS=${THREADS:-2}
W=${SIZE%x*} H=${SIZE#*x}
mkdir -p "$WORK"
WORK=$(cd "$WORK" && pwd)
DEM=$PWD/out/yarigatake_utm.tif
[ -f "$DEM" ] || "$DRIFT" import data/yarigatake_gsi_dem10b_jgd2000.tif -o "$DEM"

# The plain-ground variant of data/scenes/default.toml.
scripts/plain-ground-scene.sh "$DEM" "$W" "$H" > "$WORK/plain.toml"

# Wall seconds and max RSS (MiB) of a command, into the named variables.
measure() {
  local secs_var=$1 mib_var=$2 log=$3
  shift 3
  /usr/bin/time -f "%e %M" -o "$log.time" "$@" >"$log" 2>&1 || {
    echo "compare-cycles: error: '$*' failed; see $log" >&2
    exit 1
  }
  read -r s k <"$log.time"
  printf -v "$secs_var" "%s" "$s"
  printf -v "$mib_var" "%s" "$(python3 -c "print(round($k / 1024))")"
}

# relMSE of an EXR's RGB against a reference's: the mean squared error over
# the square of the reference's mean.
relmse() {
  local rms mean
  rms=$(oiiotool "$1" --ch R,G,B "$2" --ch R,G,B --diff 2>&1 | sed -n 's/.*RMS error = *//p')
  oiiotool "$2" --ch R,G,B -o "$WORK/rgb.exr"
  mean=$(oiiotool --stats "$WORK/rgb.exr" 2>&1 | sed -n 's/.*Stats Avg: *//p' | cut -d' ' -f1-3)
  python3 -c "m = sum(map(float, '$mean'.split())) / 3; print('%.4g' % ($rms ** 2 / m ** 2))"
}

# The two renderers' command lines (for /usr/bin/time, which runs programs,
# not shell functions): Driftscape's, then spp seed out [flags].
drift_render=("$DRIFT" render "$WORK/plain.toml" --threads "$THREADS" --exposure 0)

echo "compare-cycles: Driftscape ($SIZE, $THREADS threads)"
measure d_ref_s d_ref_mib "$WORK/drift_ref.log" "${drift_render[@]}" --spp "$REF_SPP" --seed 2 \
  -o "$WORK/drift_ref.exr" --sidecar -o "$WORK/drift_ref.json"
measure d_lo_s d_lo_mib "$WORK/drift_lo.log" "${drift_render[@]}" --spp "$SPP_LO" --seed 1 \
  -o "$WORK/drift_lo.exr"
measure d_s d_mib "$WORK/drift.log" "${drift_render[@]}" --spp "$SPP" --seed 1 \
  -o "$WORK/drift.exr" -o "$WORK/drift.png"

# The DEM as raw float32 for Blender's Python (no GDAL there).
gdal_translate -q -of ENVI -ot Float32 "$DEM" "$WORK/dem.raw"
read -r nx ny gt < <(gdalinfo -json "$DEM" | python3 -c "
import json, sys
j = json.load(sys.stdin)
print(j['size'][0], j['size'][1], ','.join(map(repr, j['geoTransform'])))")
altitude=$(python3 -c "
import json
j = json.load(open('$WORK/drift_ref.json'))
print(j['camera']['position'][2])")
cycles=("$BLENDER" -b --factory-startup --python scripts/cycles_scene.py -- dem="$WORK/dem.raw"
  width="$nx" height="$ny" gt="$gt" sidecar="$WORK/drift_ref.json" w="$W" h="$H"
  threads="$THREADS" altitude="$altitude")
echo "compare-cycles: Cycles ($("$BLENDER" --version 2>/dev/null | head -1))"
measure c_cal_s c_cal_mib "$WORK/cycles_sun.log" "${cycles[@]}" spp=1 seed=1 \
  out="$WORK/cycles_sun" sun=0
sun=$(sed -n 's/^cycles: sun_irradiance //p' "$WORK/cycles_sun.log")
measure c_ref_s c_ref_mib "$WORK/cycles_ref.log" "${cycles[@]}" spp="$REF_SPP" seed=2 \
  out="$WORK/cycles_ref.exr" sun="$sun"
measure c_lo_s c_lo_mib "$WORK/cycles_lo.log" "${cycles[@]}" spp="$SPP_LO" seed=1 \
  out="$WORK/cycles_lo.exr" sun="$sun"
measure c_s c_mib "$WORK/cycles.log" "${cycles[@]}" spp="$SPP" seed=1 out="$WORK/cycles.exr" \
  sun="$sun"
oiiotool "$WORK/cycles.exr" --ch R,G,B --tocolorspace sRGB -o "$WORK/cycles.png" 2>/dev/null || true

d_rel=$(relmse "$WORK/drift.exr" "$WORK/drift_ref.exr")
d_rel_lo=$(relmse "$WORK/drift_lo.exr" "$WORK/drift_ref.exr")
c_rel=$(relmse "$WORK/cycles.exr" "$WORK/cycles_ref.exr")
c_rel_lo=$(relmse "$WORK/cycles_lo.exr" "$WORK/cycles_ref.exr")

python3 - "$SPP" "$SPP_LO" "$d_s" "$d_lo_s" "$d_mib" "$d_rel" "$d_rel_lo" \
  "$c_s" "$c_lo_s" "$c_mib" "$c_rel" "$c_rel_lo" "$sun" <<'EOF'
import math, sys
a = sys.argv[1:]
spp, lo = int(a[0]), int(a[1])
d_s, d_lo, d_mib, d_rel, d_rel_lo = float(a[2]), float(a[3]), float(a[4]), float(a[5]), float(a[6])
c_s, c_lo, c_mib, c_rel, c_rel_lo = float(a[7]), float(a[8]), float(a[9]), float(a[10]), float(a[11])
def per_sample(t, t_lo): return (t - t_lo) / (spp - lo)
d_tps, c_tps = per_sample(d_s, d_lo), per_sample(c_s, c_lo)
d_setup, c_setup = d_s - spp * d_tps, c_s - spp * c_tps
def slope(r, r_lo): return math.log(r / r_lo) / math.log(spp / lo)
d_slope, c_slope = slope(d_rel, d_rel_lo), slope(c_rel, c_rel_lo)
# Samples Driftscape needs for Cycles' relMSE at spp, along its own slope.
d_need = spp * (c_rel / d_rel) ** (1.0 / d_slope)
print("compare-cycles: Cycles' sun lamp %.4g W/m^2 (Nishita's disc at the camera)" % float(a[12]))
print("%-28s %12s %12s %8s" % ("", "Driftscape", "Cycles", "ratio"))
rows = [("set-up s (render less samples)", d_setup, c_setup),
        ("time per sample s", d_tps, c_tps),
        ("peak memory MiB", d_mib, c_mib),
        ("relMSE at %d spp" % spp, d_rel, c_rel),
        ("relMSE at %d spp" % lo, d_rel_lo, c_rel_lo),
        ("relMSE slope", d_slope, c_slope)]
for name, d, c in rows:
    print("%-28s %12.4g %12.4g %8.3f" % (name, d, c, d / c if c else float("nan")))
print("Driftscape reaches Cycles' %d-spp relMSE at %.1f spp: %.3g s of samples against %.3g s,"
      " ratio %.3f" % (spp, d_need, d_need * d_tps, spp * c_tps, d_need * d_tps / (spp * c_tps)))
EOF
echo "compare-cycles: images in $WORK (drift.png, cycles.png)"
