// libFuzzer entry point for one target, chosen at compile time
// (-DDRIFT_FUZZ_TARGET="raster"); see scripts/fuzz.sh.
#include <cstdio>
#include <cstdlib>

#include "tests/fuzz/fuzz_targets.h"

// Checked allocations stay well below libFuzzer's -malloc_limit_mb (512 in
// scripts/fuzz.sh): a larger single allocation is unchecked, a finding. 64M
// (DRIFT_MEMORY_LIMIT overrides it) also keeps each input quick: a 35-byte
// image declaring 10000^2 pixels is refused by the check it exercises instead
// of being decoded into 400 MB (0.4-0.8 s an input, 108 such inputs in round 3).
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  setenv("DRIFT_MEMORY_LIMIT", "64M", 0);
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
