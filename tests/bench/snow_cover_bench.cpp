// Snow-cover descriptor: time and peak memory of the whole descriptor (5
// smoothing passes of region 3, TSA, transfer, altitude, sun) on the paper's
// 400 x 200 DEM size and on 4096^2 and 8192^2 DEMs; and one smoothing pass
// alone at 4096^2 for regions of 3, 15 and 150 cells (the paper's region on
// 50 m, 10 m and 1 m DEMs), whose cost should not grow with the region.
#include <benchmark/benchmark.h>

#include <cmath>

#include "snow/snow_cover.h"
#include "tests/bench/peak_memory.h"

namespace {

drift::terrain::HeightField relief(int w, int h) {
  drift::terrain::HeightField dem(w, h, 0.0f, drift::terrain::local_georeference(50.0));
  for (int row = 0; row < h; ++row)
    for (int x = 0; x < w; ++x)
      dem(x, row) = 1500.0f + 600.0f * std::sin(x * 0.05f) * std::cos(row * 0.043f) +
                    150.0f * std::sin(x * 0.31f + row * 0.17f);
  return dem;
}

void BM_SnowCover(benchmark::State& state) {
  const auto dem = relief(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const drift::snow::CoverOptions options;
  for (auto _ : state) {
    const auto result = drift::snow::snow_cover(dem, options);
    benchmark::DoNotOptimize(result.descriptor.data());
  }
  state.counters["cells/s"] =
      benchmark::Counter(static_cast<double>(dem.size()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
  state.counters["peak_MiB"] = drift::bench::peak_resident_mib();
}
BENCHMARK(BM_SnowCover)
    ->Args({400, 200})
    ->Args({4096, 4096})
    ->Args({8192, 8192})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Smooth(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  const auto dem = relief(side, side);
  const int region = static_cast<int>(state.range(1));
  for (auto _ : state) {
    const auto smoothed = drift::snow::smooth(dem, region);
    benchmark::DoNotOptimize(smoothed.data());
  }
  state.counters["cells/s"] =
      benchmark::Counter(static_cast<double>(dem.size()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
  state.counters["peak_MiB"] = drift::bench::peak_resident_mib();
}
BENCHMARK(BM_Smooth)
    ->Args({4096, 3})
    ->Args({4096, 15})
    ->Args({4096, 150})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
