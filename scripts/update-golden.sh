#!/usr/bin/env bash
# Re-renders every golden scene (tests/golden/scenes/*.toml) into
# tests/golden/reference/<name>.exr with the settings of
# tests/golden/golden_settings.cmake. Run it when a change to the renderer is
# intended, look at the new references, and commit them with the change:
#   scripts/update-golden.sh [BUILD_DIR [NAME...]]   (default: build, every scene)
# With names, only those scenes' references are rewritten.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$(realpath -m "${1:-$root/build}")"
cmake -S "$root" -B "$build" >/dev/null
cmake --build "$build" --target drift -j2
drift="$(find "$build" -type f -name drift -perm -u+x | head -n 1)"
[ -n "$drift" ] || { echo "update-golden: no drift binary under $build" >&2; exit 1; }
shopt -s nullglob
if [ $# -gt 1 ]; then
  scenes=()
  for name in "${@:2}"; do
    scene="$root/tests/golden/scenes/$name.toml"
    [ -f "$scene" ] || { echo "update-golden: no scene $scene" >&2; exit 1; }
    scenes+=("$scene")
  done
else
  scenes=("$root"/tests/golden/scenes/*.toml)
fi
[ ${#scenes[@]} -gt 0 ] || { echo "update-golden: no scenes in tests/golden/scenes" >&2; exit 1; }
for scene in "${scenes[@]}"; do
  name="$(basename "$scene" .toml)"
  cmake -DDRIFT="$drift" -DSCENE="$scene" -DWORK="$build/golden" \
        -DREFERENCE="$root/tests/golden/reference/$name.exr" -DMODE=update \
        -P "$root/tests/golden/run_golden.cmake"
done
# Re-run cmake so that scenes that just got a reference become tests.
cmake -S "$root" -B "$build" >/dev/null
echo "update-golden: ${#scenes[@]} reference(s) written; check them and commit tests/golden/reference/"
