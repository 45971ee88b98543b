#!/usr/bin/env bash
# A stage is added by a folder of its own plus the rows docs/architecture.md
# names ("Adding a stage"; issue 38): a copy of the tree with this example stage
# planted (terrain/example/, pipeline/cmd_example.cpp, tests/example/) and no
# other file edited configures; the build knows the stage's library, links it
# into drift, finds its tests and places it in the layer table; the layer check
# passes on the copy; the stage's and its command's sources compile.
#   tests/stage_example/check.sh SOURCE_DIR
set -euo pipefail
source_dir="$1"
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
trap 'exit 129' HUP
trap 'exit 130' INT
trap 'exit 143' TERM
fail() {
  echo "stage_example: $*" >&2
  exit 1
}

tree="$work/tree"
mkdir "$tree"
for item in CMakeLists.txt terrain dunes snow render pipeline tests scripts; do
  cp -r "$source_dir/$item" "$tree/"
done
rm -rf "$tree/tests/stage_example"
cp -r "$here/terrain/example" "$tree/terrain/"
cp "$here/pipeline/cmd_example.cpp" "$tree/pipeline/"
cp -r "$here/tests/example" "$tree/tests/"

build="$work/build"
cmake -S "$tree" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDRIFT_BUILD_BENCHMARKS=OFF \
  >"$work/configure.log" 2>&1 || { cat "$work/configure.log"; fail "the copy does not configure"; }
grep -qx "terrain/example: terrain terrain/example" "$build/layers.txt" ||
  fail "the layer table does not place terrain/example: $(cat "$build/layers.txt")"
grep -q "drift_example" "$build/pipeline/CMakeFiles/drift.dir/link.txt" ||
  fail "drift does not link drift_example"
[[ -f $build/tests/example/CTestTestfile.cmake ]] || fail "the build did not find tests/example"
"$tree/scripts/check-layers.sh" --table "$build/layers.txt" "$tree" >/dev/null ||
  fail "the layer check refuses the copy with the stage planted"
make -C "$build/terrain/example" ridge.o >/dev/null 2>&1 || fail "terrain/example/ridge.cpp does not compile"
make -C "$build/pipeline" cmake_pch.hxx.gch cmd_example.o >/dev/null 2>&1 || fail "pipeline/cmd_example.cpp does not compile"
echo "stage_example: the planted stage joins the build, drift's link, the tests and the layers"
