// Terrain stage throughput: import (GDAL warp to UTM, nodata fill) of the
// shipped Yarigatake DEM, and derived rasters (slope, normals, pyramid) on
// square DEMs of the sizes users render.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>

#include "terrain/derivatives.h"
#include "terrain/height_mesh.h"
#include "terrain/import.h"
#include "tests/bench/peak_memory.h"

namespace {

using drift::terrain::HeightField;

// Rolling synthetic relief (a few octaves of sines), 10 m cells.
HeightField relief(int n) {
  HeightField dem(n, n, 0.0f, drift::terrain::local_georeference(10.0));
  for (int row = 0; row < n; ++row) {
    for (int x = 0; x < n; ++x) {
      float z = 0.0f;
      for (int octave = 0; octave < 4; ++octave) {
        const float f = 0.003f * static_cast<float>(1 << octave);
        z += 400.0f / static_cast<float>(1 << octave) * std::sin(f * x + 1.3f * octave) *
             std::cos(f * 0.8f * row);
      }
      dem(x, row) = 1000.0f + z;
    }
  }
  return dem;
}

void BM_Import(benchmark::State& state) {
  const auto source =
      std::filesystem::path(DRIFT_SOURCE_DIR) / "data" / "yarigatake_gsi_dem10b_jgd2000.tif";
  double cells = 0;
  for (auto _ : state) {
    const auto result = drift::terrain::import_dem(source, {});
    cells = static_cast<double>(result.grid.size());
    benchmark::DoNotOptimize(result.grid.data());
  }
  drift::bench::report_cells(state, cells);
}
BENCHMARK(BM_Import)->Unit(benchmark::kMillisecond);

// A raster derived from the relief at 1024^2 and 4096^2: slope, normals,
// pyramid, each a benchmark of this one loop.
template <class Derive>
void BM_Derived(benchmark::State& state, Derive derive) {
  drift::bench::time_over_cells(state, relief(static_cast<int>(state.range(0))), derive);
}
void at_two_sizes(benchmark::internal::Benchmark* b) {
  b->Arg(1024)->Arg(4096)->Unit(benchmark::kMillisecond);
}
const float* slope(const HeightField& d) { return drift::terrain::slope_degrees(d).data(); }
const void* normals(const HeightField& d) { return drift::terrain::normals(d).data(); }
std::size_t pyramid(const HeightField& d) { return drift::terrain::pyramid(d).size(); }
BENCHMARK_CAPTURE(BM_Derived, slope, slope)->Apply(at_two_sizes);
BENCHMARK_CAPTURE(BM_Derived, normals, normals)->Apply(at_two_sizes);
BENCHMARK_CAPTURE(BM_Derived, pyramid, pyramid)->Apply(at_two_sizes);

// drift mesh on the imported Yarigatake DEM (1151 x 959 cells): the full
// mesh, and --decimate's RTIN at 0, 1 and 5 m (arg: centimetres; -1 = full),
// the mesh alone without the file (docs/meshes.md quotes these).
void BM_HeightMesh(benchmark::State& state) {
  static const HeightField dem =
      drift::terrain::import_dem(
          std::filesystem::path(DRIFT_SOURCE_DIR) / "data" / "yarigatake_gsi_dem10b_jgd2000.tif",
          {})
          .grid;
  const double bound = static_cast<double>(state.range(0)) / 100.0;
  std::size_t triangles = 0;
  for (auto _ : state) {
    const drift::terrain::Mesh m = bound < 0
                                       ? drift::terrain::height_field_mesh(dem, 1)
                                       : drift::terrain::decimated_height_field_mesh(dem, bound);
    triangles = m.triangle_count();
    benchmark::DoNotOptimize(m.positions.data());
  }
  state.counters["triangles"] = static_cast<double>(triangles);
  drift::bench::report_cells(state, static_cast<double>(dem.size()));
}
BENCHMARK(BM_HeightMesh)->Arg(-1)->Arg(0)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
