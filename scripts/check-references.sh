#!/usr/bin/env bash
# The reference check (docs/references.md, issue 38 item 7): every reference a
# reader is pointed to must resolve inside the repository. Run by CTest (test
# `references_resolve`; `references_resolve_catches` proves it catches the
# planted tree tests/references/planted/) and so by CI.
#   scripts/check-references.sh [ROOT]   ROOT: the source tree (default: this repo)
# Read: the comments of terrain/ snow/ dunes/ render/ pipeline/ tests/ (*.h,
# *.cpp), scripts/*.sh and the CMakeLists.txt files; the whole text of docs/*.md
# and README.md. Fails (exit 1, one line per problem) when
#   - a repository path (`terrain/parameter.h`, `render/material`,
#     `snow/stabilise_*`, `pipeline/cmd_<name>.cpp`) names nothing: a path
#     without extension counts if the folder or the path with .h or .cpp
#     exists, a pattern if it matches something; URLs and paths outside the
#     repository (../shared, /tmp, /usr ...) are not read;
#   - a file named alone (`snowfall.h`) is nowhere in the repository (a file of
#     another project is named by its path there: `openvdb/openvdb.h`);
#   - a relative Markdown link in a page does not resolve;
#   - a comment cites a work by a key ("Burley 2020", "Joe & Kuo 2008",
#     "Akenine-Moller et al. 2019", "paper 003") that is not a key of
#     docs/references.md's tables ("A, B & C 1999" and "A et al. 1999" are one
#     key);
#   - a comment cites the specification by section ("SPEC" and a number), a
#     document outside the repository.
# Needs only bash, find, sort and awk (mawk is enough): CI has no python3.
set -euo pipefail
if [[ $# -gt 1 ]]; then
  echo "usage: scripts/check-references.sh [ROOT]" >&2
  exit 2
fi
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
if [[ ! -f "$root/docs/references.md" ]]; then
  echo "check-references: no docs/references.md under '$root'" >&2
  exit 2
fi
cd "$root"
export LC_ALL=C
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Everything a reference may name: the tree without build and output folders.
find . \( -path ./.git -o -path './build*' -o -path ./out -o -path ./.cache \) -prune \
  -o -print | sed -e 's|^\./||' -e '/^\.$/d' | sort > "$work/tree"

# The files read; the planted tree of the check's own test is wrong on purpose.
planted=tests/references/planted
folders=()
for d in terrain snow dunes render pipeline tests; do
  if [[ -d $d ]]; then folders+=("$d"); fi
done
if [[ ${#folders[@]} -gt 0 ]]; then
  find "${folders[@]}" -path "$planted" -prune -o -type f \( -name '*.h' -o -name '*.cpp' \) -print
fi | sort > "$work/cpp"
{
  if [[ -d scripts ]]; then find scripts -maxdepth 1 -type f -name '*.sh'; fi
  find . \( -path ./.git -o -path './build*' -o -path ./out -o -path "./$planted" \) -prune \
    -o -type f -name CMakeLists.txt -print | sed 's|^\./||'
} | sort > "$work/hash"
{
  find docs -maxdepth 1 -type f -name '*.md'
  if [[ -f README.md ]]; then echo README.md; fi
} | sort > "$work/docs"

# Comment text as FILE<TAB>LINE<TAB>c<TAB>TEXT. C++: // and /* */ outside string
# and character literals.
cpp_comments='
FNR == 1 { inblock = 0 }
{
  s = $0; n = length(s); out = ""; i = 1
  while (i <= n) {
    c = substr(s, i, 1)
    if (inblock) {
      if (substr(s, i, 2) == "*/") { inblock = 0; i += 2; out = out " "; continue }
      out = out c; i++; continue
    }
    two = substr(s, i, 2)
    if (two == "//") { out = out substr(s, i + 2); break }
    if (two == "/*") { inblock = 1; i += 2; continue }
    if (two == "R\"" && substr(s, i + 2, 1) == "(") {
      j = index(substr(s, i + 3), ")\"")
      if (j == 0) break
      i = i + 3 + j + 1; continue
    }
    if (c == "\"" || (c == "\047" && !(i > 1 && substr(s, i - 1, 1) ~ /[0-9A-Fa-f]/))) {
      i++
      while (i <= n) { d = substr(s, i, 1); if (d == "\\") { i += 2; continue } i++; if (d == c) break }
      continue
    }
    i++
  }
  if (out ~ /[^ \t]/) print FILENAME "\t" FNR "\tc\t" out
}'
# Shell and CMake: a # at the start of a line or after a blank, outside quotes.
hash_comments='
{
  s = $0; n = length(s); q = ""; i = 1
  if (FNR == 1 && substr(s, 1, 2) == "#!") next
  while (i <= n) {
    c = substr(s, i, 1)
    if (q != "") {
      if (c == "\\" && q == "\"") { i += 2; continue }
      if (c == q) q = ""
      i++; continue
    }
    if (c == "\"" || c == "\047") { q = c; i++; continue }
    if (c == "\\") { i += 2; continue }
    if (c == "#" && (i == 1 || substr(s, i - 1, 1) ~ /[ \t]/)) {
      print FILENAME "\t" FNR "\tc\t" substr(s, i + 1); break
    }
    i++
  }
}'
{
  if [[ -s "$work/cpp" ]]; then xargs awk "$cpp_comments" < "$work/cpp"; fi
  if [[ -s "$work/hash" ]]; then xargs awk "$hash_comments" < "$work/hash"; fi
  if [[ -s "$work/docs" ]]; then xargs awk '{ print FILENAME "\t" FNR "\td\t" $0 }' < "$work/docs"; fi
} > "$work/text"

# The keys: the first cell of every table row of docs/references.md.
awk -F'|' '/^\|/ && $2 !~ /^[ \t]*(key|-+)[ \t]*$/ {
  k = $2; gsub(/^[ \t]+|[ \t]+$/, "", k); if (k != "") print k }' docs/references.md > "$work/keys"
if [[ ! -s "$work/keys" ]]; then
  echo "check-references: docs/references.md has no table of keys" >&2
  exit 2
fi

awk -F'\t' -v tree="$work/tree" -v keysfile="$work/keys" -v nfiles="$(cat "$work/cpp" "$work/hash" "$work/docs" | wc -l)" '
function trim_path(p) {
  while (p ~ /[.,:;)]$/ || (p ~ />$/ && p !~ /</)) p = substr(p, 1, length(p) - 1)
  return p
}
function glob_regex(g,   r, i, c) {
  r = ""
  for (i = 1; i <= length(g); i++) {
    c = substr(g, i, 1)
    if (c == "*") r = r "[^/]*"
    else if (c == "?") r = r "[^/]"
    else if (c ~ /[.+^$(){}|\\[\]]/) r = r "\\" c
    else r = r c
  }
  return "^" r "$"
}
function path_exists(p,   q, r, t) {
  gsub(/<[^>]*>/, "*", p)
  q = p; sub(/\/+$/, "", q)
  if (q == "") return 1
  if (q ~ /[*?]/) {
    r = glob_regex(q)
    for (t in exists) if (t ~ r) return 1
    return 0
  }
  if (q in exists) return 1
  if (p !~ /\/$/ && ((q ".h") in exists || (q ".cpp") in exists)) return 1
  return 0
}
# A relative link from a page in folder dir; 1 when it leaves the tree (not ours).
function link_exists(dir, t,   n, i, parts, out, m) {
  sub(/#.*/, "", t); sub(/\?.*/, "", t)
  if (t == "") return 1
  t = (dir == "" ? t : dir "/" t)
  n = split(t, parts, "/"); m = 0
  for (i = 1; i <= n; i++) {
    if (parts[i] == "" || parts[i] == ".") continue
    if (parts[i] == "..") { if (m == 0) return 1; m--; continue }
    out[++m] = parts[i]
  }
  t = ""
  for (i = 1; i <= m; i++) t = t (i > 1 ? "/" : "") out[i]
  return (t == "" || (t in exists))
}
# The canonical form of a key: "A, B & C 1999" and "A et al. 1999" are one.
function canon(k,   y, first) {
  gsub(/[()]/, "", k); gsub(/\047s /, " ", k); gsub(/ and /, " & ", k); gsub(/[ \t]+/, " ", k)
  sub(/^ /, "", k); sub(/ $/, "", k)
  if (k ~ /^[Pp]aper /) return "paper " substr(k, 7)
  if (k ~ /, / || k ~ / et al\.? /) {
    y = k; sub(/.* /, "", y)
    first = k; sub(/[ ,].*/, "", first)
    return first " et al. " y
  }
  return k
}
function squeeze(x) {
  gsub(/[ \t]+/, " ", x); sub(/^ /, "", x); sub(/ $/, "", x)
  return x
}
function problem(msg) {
  if (!((file SUBSEP line SUBSEP msg) in seen)) {
    seen[file, line, msg] = 1
    printf "%s:%d: %s\n", file, line, msg
    bad++
  }
}
BEGIN {
  while ((getline t < tree) > 0) {
    exists[t] = 1
    b = t; sub(/.*\//, "", b); base[b] = 1
  }
  while ((getline k < keysfile) > 0) key[canon(k)] = 1
  N = "[A-Z][-A-Za-z\047\200-\377]*[A-Za-z\200-\377]"
  Y = "(1[89][0-9][0-9]|20[0-9][0-9])"
  KEY = N "((, " N ")* (&|and) " N ")?( et al\\.?)?(\047s)? \\(?" Y "[a-z]?\\)?"
  PAPER = "[Pp]aper 0[0-9][0-9]"
  NOTNAME = "^(In|Since|Until|From|Before|After|By|Of|January|February|March|April|May|June|July|August|September|October|November|December|Issue|Version|Debian|Ubuntu)$"
  ROOTS = "(terrain|snow|dunes|render|pipeline|tests|scripts|docs|data|\\.ci)/"
}
{ f[NR] = $1; l[NR] = $2 + 0; kind[NR] = $3; txt[NR] = $4 }
END {
  for (r = 1; r <= NR; r++) {
    file = f[r]; line = l[r]; s = txt[r]
    gsub(/[A-Za-z][A-Za-z0-9+.-]*:\/\/[^ \t)>`"\047]*/, " ", s)   # URLs are not ours
    # Repository paths: a top folder of the tree not preceded by a path character
    # (so not ../shared/docs/, /usr/..., a/render/...); "./" before it is fine.
    u = " " s
    while (match(u, "[^-A-Za-z0-9_./~](\\./)?" ROOTS "[-A-Za-z0-9_.*?/<>+]*")) {
      p = substr(u, RSTART + 1, RLENGTH - 1); u = substr(u, RSTART + RLENGTH)
      sub(/^\.\//, "", p); p = trim_path(p)
      paths++
      if (!path_exists(p))
        problem("\"" p "\" names nothing in the repository (" \
                (p ~ /[*?<]/ ? "the pattern matches nothing" : \
                 (p ~ /\/$/ ? "no such folder" : \
                  (p ~ /\.[A-Za-z]+$/ ? "no such file or folder" : \
                   "no such folder, nor " p ".h or " p ".cpp"))) \
                "); correct the path or drop it")
    }
    # Files named alone.
    u = " " s
    while (match(u, "[ \t(`\"\047][A-Za-z0-9_+-]+\\.(h|cpp|md|sh)([^A-Za-z0-9_/]|$)")) {
      p = substr(u, RSTART + 1, RLENGTH - 1); u = substr(u, RSTART + RLENGTH - 1)
      sub(/[^A-Za-z0-9]$/, "", p)
      paths++
      if (!(p in base))
        problem("\"" p "\" is no file of the repository; name ours by its path, another project\047s by its path there (openvdb/openvdb.h)")
    }
    # Markdown links in pages.
    if (kind[r] == "d") {
      u = s; dir = file; if (dir ~ /\//) sub(/\/[^\/]*$/, "", dir); else dir = ""
      while (match(u, /\]\([^) \t]+\)/)) {
        t = substr(u, RSTART + 2, RLENGTH - 3); u = substr(u, RSTART + RLENGTH)
        if (t ~ /^[A-Za-z][A-Za-z0-9+.-]*:/ || t ~ /^#/ || t ~ /^\//) continue
        paths++
        if (!link_exists(dir, t)) problem("link \"" t "\" resolves to nothing from " (dir == "" ? "the top" : dir "/") "; correct it")
      }
      continue
    }
    # Keys: read across the neighbouring comment lines, counted on the line
    # where the citation starts.
    pre = ""; post = ""; s = squeeze(s)
    if (r > 1 && f[r - 1] == file && l[r - 1] == line - 1) pre = squeeze(txt[r - 1]) " "
    if (r < NR && f[r + 1] == file && l[r + 1] == line + 1) post = " " squeeze(txt[r + 1])
    u = pre s post; at = 0; lo = length(pre); hi = length(pre) + length(s)
    while (match(u, KEY "|" PAPER)) {
      m = substr(u, RSTART, RLENGTH); start = at + RSTART; nextc = substr(u, RSTART + RLENGTH, 1)
      at += RSTART + RLENGTH - 1; u = substr(u, RSTART + RLENGTH)
      if (nextc ~ /[0-9]/) continue
      first = m; sub(/[ ,\047].*/, "", first)
      if (first ~ NOTNAME) continue
      if (start <= lo || start > hi) continue
      cites++
      if (m ~ /\)$/ && m !~ /\(/) m = substr(m, 1, length(m) - 1)
      if (!(canon(m) in key))
        problem("\"" m "\" is not a key of docs/references.md; add its row there (authors, title, venue, year; used in) or cite an existing key")
    }
    u = " " s
    while (match(u, /[^A-Za-z0-9_]SPEC( section)? ?[0-9][0-9a-z.]*/)) {
      m = substr(u, RSTART + 1, RLENGTH - 1); u = substr(u, RSTART + RLENGTH)
      sub(/\.$/, "", m)
      problem("cites \"" m "\", a document outside the repository; cite the docs/ page and section that records the decision, or the paper and equation")
    }
  }
  if (bad == 0) printf "check-references: %d files, %d paths and %d keys cited, all resolve\n", nfiles, paths, cites
  else printf "check-references: %d problem%s\n", bad, (bad == 1 ? "" : "s")
  exit (bad > 0 ? 1 : 0)
}' "$work/text"
