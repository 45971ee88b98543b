// Peak resident memory of this process, for benchmarks to report next to
// throughput (benchmark counters "peak_MiB"), and the one place the
// benchmarks set both counters.
#pragma once

#include <benchmark/benchmark.h>

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

// Sets the counters a benchmark over a grid reports: "cells/s", `cells` a
// run over the time taken, and "peak_MiB".
inline void report_cells(benchmark::State& state, double cells) {
  state.counters["cells/s"] = benchmark::Counter(cells * static_cast<double>(state.iterations()),
                                                 benchmark::Counter::kIsRate);
  state.counters["peak_MiB"] = peak_resident_mib();
}

// Times run(grid) for as long as the benchmark asks, then reports its cells
// as report_cells() does. `run` returns something of its result (a pointer to
// its values) for the compiler to keep.
template <class Grid, class Run>
void time_over_cells(benchmark::State& state, const Grid& grid, Run run) {
  for (auto _ : state) benchmark::DoNotOptimize(run(grid));
  report_cells(state, static_cast<double>(grid.size()));
}

}  // namespace drift::bench
