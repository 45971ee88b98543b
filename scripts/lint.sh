#!/usr/bin/env bash
# Static checks on our own code: clang-format (report only), clang-tidy and cppcheck.
# Needs a configured build/ (compile_commands.json): run scripts/build.sh first.
#   scripts/lint.sh [--no-tidy]
# --no-tidy: clang-format's report and cppcheck on every file of ours (about 18 s
# of CPU), without clang-tidy (about 21-33 s of CPU a file, over half an hour on
# 2 cores for the tree: docs/testing.md). CI (.ci/run) runs clang-tidy on the
# files the last ten commits changed, at most 20 (DRIFT_TIDY_SINCE, DRIFT_TIDY_MAX).
set -uo pipefail
cd "$(dirname "$0")/.."
tidy=1
if [ "${1:-}" = --no-tidy ]; then tidy=0; fi
mapfile -t sources < <(git ls-files '*.cpp' '*.h' | grep -E '^(terrain|render|snow|dunes|pipeline|tests)/')
status=0
# Reports in a private folder (never a predictable name in /tmp), removed on exit.
reports=$(mktemp -d)
trap 'rm -rf "$reports"' EXIT
trap 'exit 129' HUP
trap 'exit 130' INT
trap 'exit 143' TERM
echo "== clang-format"
unformatted=$(clang-format --dry-run "${sources[@]}" 2>&1 | grep -c "warning:" || true)
echo "clang-format: $unformatted places differ from .clang-format"
echo "== clang-tidy"
mapfile -t cpps < <(printf '%s\n' "${sources[@]}" | grep -E '\.cpp$' | grep -v '^tests/')
all_cpps=("${cpps[@]}")  # cppcheck takes them all, whatever clang-tidy takes
if [ $tidy = 1 ]; then
# DRIFT_TIDY_SINCE=REV (a branch: its merge base with main; CI: HEAD~10): clang-tidy
# only on the files changed since REV, about 21-33 s of CPU a file, the most
# recently changed first; all of them if REV is unknown. DRIFT_TIDY_MAX=N (CI: 20)
# keeps the first N of those, so that the stage has a bound (docs/testing.md).
if [ -n "${DRIFT_TIDY_SINCE:-}" ] && git rev-parse -q --verify "$DRIFT_TIDY_SINCE^{commit}" >/dev/null; then
  mapfile -t changed < <(git log --format= --name-only "$DRIFT_TIDY_SINCE..HEAD" -- '*.cpp' |
    awk 'NF && !seen[$0]++')
  mapfile -t cpps < <(printf '%s\n' "${changed[@]}" | grep -Fxf <(printf '%s\n' "${cpps[@]}") || true)
  echo "clang-tidy: ${#cpps[@]} files changed since $DRIFT_TIDY_SINCE"
fi
if [ -n "${DRIFT_TIDY_MAX:-}" ] && [ ${#cpps[@]} -gt "$DRIFT_TIDY_MAX" ]; then
  echo "clang-tidy: the $DRIFT_TIDY_MAX most recently changed of them (DRIFT_TIDY_MAX)"
  cpps=("${cpps[@]:0:$DRIFT_TIDY_MAX}")
fi
# The build precompiles CLI11 with GCC; clang cannot read GCC's PCH, so give
# clang-tidy a copy of the compile database without the PCH include.
mkdir -p build/tidy
python3 - <<'PY'
import json, re
db = json.load(open("build/compile_commands.json"))
for entry in db:
    entry["command"] = re.sub(r"-Xclang -include-pch -Xclang \S+|-include \S+cmake_pch\.hxx|-Winvalid-pch", "", entry["command"])
json.dump(db, open("build/tidy/compile_commands.json", "w"))
PY
# A few files a process, one process a core.
[ ${#cpps[@]} -gt 0 ] && printf '%s\0' "${cpps[@]}" |
  xargs -0 -n 4 -P "${DRIFT_JOBS:-$(nproc)}" clang-tidy -p build/tidy --quiet 2>/dev/null |
  grep -E "warning:|error:" | sed "s|^$PWD/||" | sort -u | tee "$reports/tidy.txt"
# A finding fails the lint in a file a whole run found clean (.ci/tidy-clean.txt,
# one path a line: the ratchet, since no whole run of the tree is clean yet);
# in any other file it is reported, to be fixed when that file's run is recorded.
if [ -s "$reports/tidy.txt" ]; then
  if grep -E -v '^\s*(#|$)' .ci/tidy-clean.txt 2>/dev/null | sed 's|$|:|' |
    grep -F -f - "$reports/tidy.txt" >"$reports/tidy-clean-files.txt"; then
    echo "clang-tidy: findings in files recorded clean (.ci/tidy-clean.txt):"
    cat "$reports/tidy-clean-files.txt"
    status=1
  else
    echo "clang-tidy: $(wc -l <"$reports/tidy.txt") findings, none in a file recorded clean (reported only)"
  fi
fi
else
  echo "clang-tidy: skipped (--no-tidy)"
fi
echo "== cppcheck"
cppcheck --quiet --std=c++20 --language=c++ --enable=warning,performance,portability \
  --inline-suppr --suppress=missingIncludeSystem -I . "${all_cpps[@]}" 2>&1 | tee "$reports/cppcheck.txt"
[ -s "$reports/cppcheck.txt" ] && status=1
exit $status
