// Peak resident memory of this process, for benchmarks to report next to
// throughput (benchmark counters "peak_MiB").
#pragma once

#include <cstdint>

namespace drift::bench {

// VmHWM from /proc/self/status, in bytes.
std::uint64_t peak_resident_bytes();

// Peak resident memory in MiB, as a double for benchmark::Counter.
inline double peak_resident_mib() {
  return static_cast<double>(peak_resident_bytes()) / (1024.0 * 1024.0);
}

}  // namespace drift::bench
