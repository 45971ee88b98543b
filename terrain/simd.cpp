#include "terrain/simd.h"

#include <atomic>
#include <cstdlib>
#include <cstring>

namespace drift::simd {

namespace {

Isa detect() {
#ifdef DRIFT_SIMD_X86
  const char* forced = std::getenv("DRIFT_SIMD");
  if (forced && std::strcmp(forced, "sse2") == 0) return Isa::Sse2;
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2")) return Isa::Avx2;
#endif
  return Isa::Sse2;
}

std::atomic<Isa>& current() {
  static std::atomic<Isa> isa{detect()};
  return isa;
}

}  // namespace

Isa active() { return current().load(std::memory_order_relaxed); }

Limit::Limit(Isa isa) : previous_(active()) {
  if (static_cast<int>(isa) < static_cast<int>(previous_)) current().store(isa);
}

Limit::~Limit() { current().store(previous_); }

}  // namespace drift::simd
