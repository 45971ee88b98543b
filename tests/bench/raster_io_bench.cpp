// Raster I/O throughput: GeoTIFF write and read of square float32 rasters.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "terrain/raster_io.h"
#include "tests/bench/peak_memory.h"

namespace {

void BM_GeoTiffRoundTrip(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  drift::terrain::HeightField grid(n, n, 0.0f, drift::terrain::local_georeference(1.0));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) grid(x, y) = static_cast<float>((x * 7 + y * 13) % 1000) * 0.5f;
  const auto path = std::filesystem::temp_directory_path() / "drift_bench_io.tif";
  for (auto _ : state) {
    drift::terrain::write_geotiff(grid, path);
    auto back = drift::terrain::read_raster(path);
    benchmark::DoNotOptimize(back.data());
  }
  drift::bench::report_cells(state, static_cast<double>(n) * n);
  std::filesystem::remove(path);
}
BENCHMARK(BM_GeoTiffRoundTrip)->Arg(1024)->Arg(4096)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
