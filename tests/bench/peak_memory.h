// Peak resident memory of this process, for benchmarks to report next to
// throughput (benchmark counters "peak_MiB").
#pragma once

#include <cstdint>

namespace drift::bench {

// VmHWM from /proc/self/status, in bytes.
std::uint64_t peak_resident_bytes();

// VmRSS from /proc/self/status (resident now), in bytes.
std::uint64_t resident_bytes();

// Resets the peak to the current resident size (Linux >= 4.0:
// /proc/self/clear_refs), so that a benchmark can measure one stage's peak.
void reset_peak_resident();

// Peak resident memory in MiB, as a double for benchmark::Counter.
inline double peak_resident_mib() {
  return static_cast<double>(peak_resident_bytes()) / (1024.0 * 1024.0);
}

}  // namespace drift::bench
