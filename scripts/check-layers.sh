#!/usr/bin/env bash
# The include-layer check (docs/architecture.md): fails when a module includes
# a module above it or beside it. Run by CTest (test `include_layers`) and so
# by CI.
#   scripts/check-layers.sh [ROOT]   ROOT: the source tree (default: this repo)
# Layers, bottom up; a module may include only the modules listed for it:
#   terrain (core)        terrain
#   terrain/offscreen     terrain, offscreen
#   dunes                 terrain, dunes
#   snow                  terrain, offscreen, snow
#   terrain/marks         terrain, offscreen, marks
#   terrain/soil          terrain, offscreen, soil
#   render                terrain, render
#   pipeline              everything
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$root"

# The module of a path inside the tree ("terrain/marks/marks.h" -> marks).
module_of() {
  case "$1" in
    terrain/marks/*) echo marks ;;
    terrain/soil/*) echo soil ;;
    terrain/offscreen/*) echo offscreen ;;
    terrain/*) echo terrain ;;
    *) echo "${1%%/*}" ;;
  esac
}

allowed() {  # allowed FROM TO
  case "$1" in
    terrain) [[ $2 == terrain ]] ;;
    offscreen) [[ $2 == terrain || $2 == offscreen ]] ;;
    dunes) [[ $2 == terrain || $2 == dunes ]] ;;
    snow | marks | soil) [[ $2 == terrain || $2 == offscreen || $2 == "$1" ]] ;;
    render) [[ $2 == terrain || $2 == render ]] ;;
    pipeline) true ;;
    *) false ;;
  esac
}

status=0
checked=0
while IFS= read -r file; do
  from=$(module_of "$file")
  checked=$((checked + 1))
  while IFS=: read -r line include; do
    to=$(module_of "$include")
    case "$to" in terrain | offscreen | dunes | snow | marks | soil | render | pipeline) ;; *) continue ;; esac
    if ! allowed "$from" "$to"; then
      echo "$file:$line: $from includes \"$include\" ($to is above or beside it; see docs/architecture.md)"
      status=1
    fi
  done < <(grep -n -oE '^[[:space:]]*#[[:space:]]*include[[:space:]]+"[^"]+"' "$file" |
           sed -E 's/^([0-9]+):.*"([^"]+)"/\1:\2/')
done < <(find terrain dunes snow render pipeline -type f \( -name '*.h' -o -name '*.cpp' \) 2>/dev/null | sort)

if [[ $checked == 0 ]]; then
  echo "check-layers: no sources under $root" >&2
  exit 2
fi
if [[ $status == 0 ]]; then echo "check-layers: $checked files, every include within its layer"; fi
exit $status
