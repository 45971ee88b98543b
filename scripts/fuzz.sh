#!/usr/bin/env bash
# Fuzzes every reader of outside input (tests/fuzz/fuzz_targets.h) with libFuzzer:
# builds the targets with clang, AddressSanitizer and UndefinedBehaviorSanitizer
# into build-fuzz/ and runs each for SECONDS (default 60), niced.
#   scripts/fuzz.sh [SECONDS] [TARGET...]   targets: raster scene objects track scenario obj ply image mesh glb
# The timeout (60 s per input) is wall-clock: generous, as a niced fuzzer on a
# busy machine gets little CPU (a 2 s unit once took 24 s so). The targets run
# with DRIFT_MEMORY_LIMIT=64M (tests/fuzz/fuzz_main.cpp): a single allocation
# of 512 MB or more (-malloc_limit_mb; image: 64 MB) is unchecked by
# terrain/memory.h, a finding.
# New inputs collect in build-fuzz/corpus/<target>/; a crash, leak or hang is
# written to build-fuzz/findings/<target>/ and stops that target. Keep each
# finding as a regression input under tests/fuzz/regressions/<target>/ (the
# suite replays them) once it is fixed. Needs clang and libclang-rt-14-dev.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then targets=(raster scene objects track scenario obj ply image mesh glb); fi

CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDRIFT_FUZZ=ON \
  -DDRIFT_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz -j "${DRIFT_JOBS:-2}" --target "${targets[@]/#/fuzz_}"

status=0
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/findings/$t"
  echo "fuzz: $t for ${seconds} s"
  # Images are read within DRIFT_MEMORY_LIMIT (64M) and EXR headers within
  # their file's size (render/exr_header.cpp): the image target allows no
  # single allocation over 64 MB.
  malloc_limit=512
  if [ "$t" = image ]; then malloc_limit=64; fi
  # OSMesa is not linked here; GDAL keeps driver state for the process's life.
  # Leaks known inside system libraries are suppressed as in the sanitizer
  # suite (tests/sanitize/lsan.supp: OpenImageIO's geterror after a failed read).
  if ! ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 \
    LSAN_OPTIONS="suppressions=$PWD/tests/sanitize/lsan.supp:print_suppressions=0" \
    UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
    nice -n 19 "build-fuzz/tests/fuzz/fuzz_$t" "build-fuzz/corpus/$t" "tests/fuzz/corpus/$t" \
    -max_total_time="$seconds" -timeout=60 -rss_limit_mb=4096 -malloc_limit_mb="$malloc_limit" -max_len=65536 \
    -artifact_prefix="build-fuzz/findings/$t/" -print_final_stats=1 \
    2> "build-fuzz/findings/$t.log"; then
    echo "fuzz: $t FOUND something: see build-fuzz/findings/$t/ and build-fuzz/findings/$t.log"
    status=1
  fi
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "build-fuzz/findings/$t.log" || true
done
exit $status
