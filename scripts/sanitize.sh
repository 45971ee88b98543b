#!/usr/bin/env bash
# Builds the whole suite with AddressSanitizer and UndefinedBehaviorSanitizer
# (GCC 12's libasan/libubsan, which come with g++) into build-asan/ and runs all
# of it, golden-image tests included; the first report of either stops the
# process (halt_on_error) and fails its test. Built -O1 -g1 as Release with
# assertions kept (RelWithDebInfo would set NDEBUG and drop them); -g1: line
# tables only, all a report's stack needs (function, file, line), a third less
# compile time than -g and objects a third the size (docs/testing.md). Known reports
# inside system libraries are suppressed by name, each with a comment: leaks in
# tests/sanitize/lsan.supp. On 2 cores it takes about 14 min to build from
# scratch and 8 min to run (measurements in docs/testing.md).
#   scripts/sanitize.sh [--inputs] [ctest arguments...]
# --inputs (CI, .ci/run): only the tests of what reads outside input and sizes
# memory by it: the fuzz corpora and regressions (fuzz_replay), the readers'
# allocation bounds (reader_allocation), the readers and writers of terrain/
# (terrain_tests) and every subcommand's refusals and outputs (pipeline_tests),
# building only drift and those targets (docs/testing.md has the figures).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${DRIFT_JOBS:-$(nproc)}"
targets=(all)
select=(-LE gallery)
if [ "${1:-}" = --inputs ]; then
  shift
  targets=(drift fuzz_replay reader_allocation terrain_tests pipeline_tests)
  select=(-L '^(fuzz_replay|reader_allocation|terrain_tests|pipeline_tests)$')
fi
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Release -DDRIFT_ASSERTIONS=ON \
  "-DCMAKE_CXX_FLAGS_RELEASE=-O1 -g1" "-DCMAKE_C_FLAGS_RELEASE=-O1 -g1" \
  -DDRIFT_SANITIZE=ON -DDRIFT_BUILD_BENCHMARKS=OFF "${launcher[@]}" >/dev/null
cmake --build build-asan -j "$jobs" --target "${targets[@]}"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1"
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitize/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# The gallery test (a few minutes of every stage at full size) runs in the
# plain suite only: under the sanitizers it would take most of an hour.
ctest --test-dir build-asan --output-on-failure -j "$jobs" "${select[@]}" "$@"
