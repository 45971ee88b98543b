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

// Wall-clock milliseconds (the descriptor runs on every core).
void wall_ms(benchmark::internal::Benchmark* b) { b->Unit(benchmark::kMillisecond)->UseRealTime(); }

// The whole descriptor at its defaults (what the loop keeps: its values).
const void* cover(const drift::terrain::HeightField& dem) {
  return drift::snow::snow_cover(dem, drift::snow::CoverOptions{}).descriptor.data();
}

void BM_SnowCover(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  drift::bench::time_over_cells(state, relief(w, h), cover);
}
BENCHMARK(BM_SnowCover)->Args({400, 200})->Args({4096, 4096})->Args({8192, 8192})->Apply(wall_ms);

void BM_Smooth(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0)), region = static_cast<int>(state.range(1));
  drift::bench::time_over_cells(state, relief(side, side),
                                [region](const drift::terrain::HeightField& dem) {
                                  return drift::snow::smooth(dem, region).data();
                                });
}
BENCHMARK(BM_Smooth)->ArgsProduct({{4096}, {3, 15, 150}})->Apply(wall_ms);

}  // namespace

BENCHMARK_MAIN();
