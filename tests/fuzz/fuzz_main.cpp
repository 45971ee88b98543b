// libFuzzer entry point for one target, chosen at compile time
// (-DDRIFT_FUZZ_TARGET="raster"); see scripts/fuzz.sh.
#include <cstdio>
#include <cstdlib>

#include "tests/fuzz/fuzz_targets.h"

// Checked allocations stay well below libFuzzer's -rss_limit_mb (4096 in
// scripts/fuzz.sh): anything larger that is still allocated is unchecked.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  setenv("DRIFT_MEMORY_LIMIT", "2G", 1);
  drift::fuzz::bound_work_per_input();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (!drift::fuzz::run_target(DRIFT_FUZZ_TARGET, data, size)) {
    std::fprintf(stderr, "no fuzz target '%s'\n", DRIFT_FUZZ_TARGET);
    std::abort();
  }
  return 0;
}
