#!/usr/bin/env bash
# A stage is added by a folder of its own plus the rows docs/architecture.md
# names ("Adding a stage"; issue 38): a copy of the tree with this example stage
# planted (terrain/example/, pipeline/cmd_example.cpp, tests/example/) and no
# other file edited configures; the build knows the stage's library, links it
# into drift, finds its tests and places it in the layer table; the layer check
# passes on the copy; drift builds, runs `drift example` and renders the ridge
# it writes, and the stage's own test passes.
#
# The copy is built as scripts/build.sh builds the tree, through ccache when it
# is installed (scripts/install-deps.sh installs it, scripts/ccache-env.sh sets
# it up). The copy lies in a private folder inside the suite's build folder and
# is built at the same depth below its sources, so ccache finds every unchanged
# object of the suite's own build: the copy's build takes a minute or two, not
# a full build's ten.
#   tests/stage_example/check.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
source_dir=$(cd "$1" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d "$2/stage_example.XXXXXX")
trap 'rm -rf "$work"' EXIT
trap 'exit 129' HUP
trap 'exit 130' INT
trap 'exit 143' TERM
fail() {
  echo "stage_example: $*" >&2
  exit 1
}

tree="$work/src"
mkdir "$tree"
for item in CMakeLists.txt terrain dunes snow render pipeline tests scripts; do
  cp -r "$source_dir/$item" "$tree/"
done
rm -rf "$tree/tests/stage_example"
cp -r "$here/terrain/example" "$tree/terrain/"
cp "$here/pipeline/cmd_example.cpp" "$tree/pipeline/"
cp -r "$here/tests/example" "$tree/tests/"

build="$tree/build"
# shellcheck source=scripts/ccache-env.sh
export CCACHE_BASEDIR="$source_dir"
source "$tree/scripts/ccache-env.sh" "$source_dir"
cmake -S "$tree" -B "$build" -DCMAKE_BUILD_TYPE=Release "${drift_launcher[@]}" \
  >"$work/configure.log" 2>&1 || { cat "$work/configure.log"; fail "the copy does not configure"; }
grep -qx "terrain/example: terrain terrain/example" "$build/layers.txt" ||
  fail "the layer table does not place terrain/example: $(cat "$build/layers.txt")"
grep -q "drift_example" "$build/pipeline/CMakeFiles/drift.dir/link.txt" ||
  fail "drift does not link drift_example"
[[ -f $build/tests/example/CTestTestfile.cmake ]] || fail "the build did not find tests/example"
"$tree/scripts/check-layers.sh" --table "$build/layers.txt" "$tree" >/dev/null ||
  fail "the layer check refuses the copy with the stage planted"

cmake --build "$build" -j "${DRIFT_JOBS:-2}" --target drift example_tests >"$work/build.log" 2>&1 ||
  { tail -30 "$work/build.log"; fail "drift does not build with the stage planted"; }
ctest --test-dir "$build" -R '^ExampleStage\.' --output-on-failure >"$work/ctest.log" 2>&1 ||
  { cat "$work/ctest.log"; fail "the stage's own test fails"; }
grep -q "100% tests passed" "$work/ctest.log" || fail "ctest did not run the stage's test"

drift="$build/pipeline/drift"
"$drift" --help | grep -q "^  example" || fail "drift --help does not list the example subcommand"
"$drift" example --size 64 -o "$work/ridge.tif" || fail "drift example failed"
cat >"$work/ridge.toml" <<SCENE
[terrain]
raster = "$work/ridge.tif"
[sun]
azimuth = 135
elevation = 30
[camera]
from = [32, -60, 60]
to = [32, -32, 0]
fov = 50
[render]
width = 64
height = 36
spp = 2
SCENE
"$drift" render "$work/ridge.toml" -o "$work/ridge.png" --threads 1 >"$work/render.log" 2>&1 ||
  { cat "$work/render.log"; fail "drift render does not render the stage's product"; }
[[ -s $work/ridge.png ]] || fail "drift render wrote no image of the ridge"
echo "stage_example: the planted stage joins the build, drift, the tests and the layers;" \
  "drift example ran and its ridge rendered"
