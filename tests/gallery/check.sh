#!/usr/bin/env bash
# The whole gallery builds into an empty folder (issue 38, item 6): a copy of
# data/ in a private folder, so that a scene or rule that read a product from
# anywhere but OUT (the scenes' default, ../../out, or the repository's out/)
# finds nothing there and fails; `make -j2 OUT=DIR SIZE=96x54 SPP=1` then runs
# every stage and render of `all`, the dataset and the flyover. Checked: make
# succeeds, every image it promises exists at the overriding size, and nothing
# was written beside the scenes.
#   tests/gallery/check.sh SOURCE_DIR DRIFT BUILD_DIR
set -euo pipefail
source_dir=$(cd "$1" && pwd)
drift="$2"
work=$(mktemp -d "$3/gallery.XXXXXX")
trap 'rm -rf "$work"' EXIT
trap 'exit 129' HUP
trap 'exit 130' INT
trap 'exit 143' TERM
fail() {
  echo "gallery: $*" >&2
  exit 1
}

cp -r "$source_dir/data" "$work/data"
out="$work/gallery"
find "$work/data" -type f | sort >"$work/before"
make -C "$work/data/scenes" -j "${DRIFT_JOBS:-2}" DRIFT="$drift" OUT="$out" THREADS=1 \
  SIZE=96x54 SPP=1 MAP_CELL=400 all dataset flyover >"$work/make.log" 2>&1 ||
  { tail -40 "$work/make.log"; fail "make did not build the gallery into an empty folder"; }
find "$work/data" -type f | sort >"$work/after"
diff "$work/before" "$work/after" >&2 || fail "the gallery wrote beside the scenes, not into OUT"
[[ ! -e $work/out ]] || fail "the gallery wrote into the scenes' default ../../out"

# A PNG's width and height (its IHDR chunk, bytes 17-24, big-endian).
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{ printf "%dx%d", $1*16777216+$2*65536+$3*256+$4, $5*16777216+$6*65536+$7*256+$8 }'; }
images=(default.png desert.png snowfall.png snowfall_start.png snowfall_rock.png
  snow_summit.png ridge.png horizon.png clouds.png marks_walk.png marks_tyres.png
  marks_snow_walk.png marks_dragged.png marks_ball_object.png
  daylight/noon.png snow/radius20.png marks/print_sand.png soil/cone.png soil/yarigatake.png
  dataset/view1.png flyover/frame_0.png light_shafts/on.png)
for image in "${images[@]}"; do
  [[ -s $out/$image ]] || fail "make did not render $image"
  [[ $(png_size "$out/$image") == 96x54 ]] ||
    fail "$image is $(png_size "$out/$image"), not the overriding SIZE 96x54"
done
for sheet in noon_sunset.png snow_radius.png snow_region.png marks_materials.png \
  marks_sweep.png marks_sigma.png soil_types.png light_shafts.png flyover.png yarigatake_map.png; do
  [[ -s $out/$sheet ]] || fail "make did not make $sheet"
done
[[ -s $out/dataset/view1.json && -s $out/dataset/view1.exr ]] || fail "the dataset lacks view1's EXR or sidecar"
echo "gallery: every stage and render of the gallery built into an empty folder at 96x54, 1 spp"
