#!/usr/bin/env bash
# The include-layer check (docs/architecture.md). Fails closed: on an include
# that crosses into a folder its own folder may not use, on any source folder
# or include it cannot place, and on an include loop between two files of one
# folder. Run by CTest (tests `include_layers*`) and so by CI.
#   scripts/check-layers.sh [--table LAYERS.txt] [ROOT]
# ROOT: the source tree (default: this repo). LAYERS.txt: which folders each
# folder may include, one line "folder: allowed..."; CMake derives it from the
# link graph at configure time (default: ROOT/build/layers.txt), so a module's
# layer is whatever its CMakeLists.txt links, written down nowhere else.
set -euo pipefail
table=""
if [[ ${1:-} == --table ]]; then
  table="$2"
  shift 2
fi
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
table="${table:-$root/build/layers.txt}"
if [[ ! -r $table ]]; then
  echo "check-layers: no layer table '$table'; configure the build first (scripts/build.sh) or pass --table" >&2
  exit 2
fi
table=$(realpath -m "$table")
cd "$root"

declare -A allowed_of # folder -> " allowed folders "
while IFS= read -r row; do
  [[ -z $row || $row == \#* ]] && continue
  allowed_of["${row%%:*}"]=" ${row#*: } "
done <"$table"
if [[ ${#allowed_of[@]} == 0 ]]; then
  echo "check-layers: the layer table '$table' names no folder" >&2
  exit 2
fi

# The source files of the tree; tests/ may include anything, build trees and
# data hold no sources of ours.
mapfile -t files < <(find . \( -name .git -o -name 'build*' -o -name tests -o -name data \
                               -o -name docs -o -name scripts -o -name out \) -prune -o \
                          -type f \( -name '*.h' -o -name '*.hpp' -o -name '*.c' -o -name '*.cc' \
                                     -o -name '*.cpp' \) -print | sed 's|^\./||' | sort)
if [[ ${#files[@]} == 0 ]]; then
  echo "check-layers: no sources under $root" >&2
  exit 2
fi

status=0
declare -A unplaced=()
edges=()
for file in "${files[@]}"; do
  from=$(dirname "$file")
  if [[ -z ${allowed_of[$from]+x} ]]; then
    if [[ -z ${unplaced[$from]+x} ]]; then
      echo "$file: folder '$from' belongs to no module the build knows (give it a CMakeLists.txt target, or move the file into a module)"
      unplaced[$from]=1
    fi
    status=1
    continue
  fi
  while IFS=: read -r line include; do
    # Resolve as the compiler does: beside the file, then from the root.
    if [[ -e $from/$include ]]; then
      target=$(realpath -m --relative-to=. "$from/$include")
    elif [[ -e $include ]]; then
      target="$include"
    else
      target="$include" # not in this tree (a planted fixture): placed by its path
    fi
    to=$(dirname "$target")
    if [[ -z ${allowed_of[$to]+x} ]]; then
      echo "$file:$line: includes \"$include\", which no module of the build holds"
      status=1
    elif [[ ${allowed_of[$from]} != *" $to "* ]]; then
      echo "$file:$line: $from includes \"$include\" ($to is above or beside it; $from may include:${allowed_of[$from]% }; see docs/architecture.md)"
      status=1
    elif [[ $to == "$from" && ${target%.*} != "${file%.*}" ]]; then
      edges+=("${file%.*} ${target%.*}") # a header and its source are one component
    fi
  done < <(grep -n -oE '^[[:space:]]*#[[:space:]]*include[[:space:]]+"[^"]+"' "$file" |
           sed -E 's/^([0-9]+):.*"([^"]+)"/\1:\2/')
done

# Include loops inside a folder: tsort names the components of each loop.
if [[ ${#edges[@]} -gt 0 ]]; then
  if ! loops=$(printf '%s\n' "${edges[@]}" | tsort 2>&1 >/dev/null); then
    echo "include loop between components of one folder (break it with a header of its own):"
    echo "$loops" | sed -nE 's/^tsort: ([^-].*)$/  \1/p' | grep -v 'input contains a loop' || true
    status=1
  fi
fi

if [[ $status == 0 ]]; then
  echo "check-layers: ${#files[@]} files in ${#allowed_of[@]} folders, every include within its layer, no include loop"
fi
exit $status
