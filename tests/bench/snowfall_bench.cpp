// Snowfall (paper 003) per stage on synthetic mountains with 1 m cells: the depth
// maps and probability (horizon sweep or OSMesa for the ground; OSMesa for the
// objects), ground stabilisation, and the whole stage with ~10k object triangles.
// Counters: seconds per depth map, peak resident memory.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>

#include "snow/snowfall.h"
#include "snow/snowfall_directions.h"
#include "snow/stabilise_grid.h"
#include "terrain/mesh_io.h"
#include "tests/bench/peak_memory.h"
#include "tests/dem_fixture.h"

namespace {

using namespace drift::snow;

drift::terrain::HeightField mountains(int n) { return drift::testing::snowfall_mountains(n); }

// Hut, bench, tree and eight rocks near the middle, standing on the ground
// (same formula as mountains(), y north = -row): ~11k triangles.
std::vector<drift::terrain::PlacedMesh> objects(int n) {
  std::vector<drift::terrain::PlacedMesh> out;
  auto put = [&](const char* name, double x, double y) {
    const double z = 200 * std::sin(x / 300.0) * std::cos(-y / 450.0) +
                     60 * std::sin(x / 70.0 - y / 90.0) +
                     10 * std::sin(x / 13.0) * std::cos(-y / 17.0);
    drift::terrain::PlacedMesh& placed = out.emplace_back();
    placed.mesh = drift::terrain::read_obj(std::string(DRIFT_SOURCE_DIR "/data/objects/") + name);
    placed.position = Eigen::Vector3d(x, y, z);
  };
  const double c = n / 2.0;
  put("hut.obj", c, -c);
  put("bench.obj", c + 8, -c + 3);
  put("tree.obj", c - 9, -c - 6);
  for (int k = 0; k < 4; ++k) {
    put("rock_a.obj", c + 15 + 5 * k, -c + 10);
    put("rock_b.obj", c - 15 - 4 * k, -c - 12);
  }
  return out;
}

void BM_SnowProbability(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0)), maps = static_cast<int>(state.range(1));
  const bool gl = state.range(2) != 0;
  const SnowScene scene = make_snow_scene(mountains(n), {}, 0.0);
  const auto dirs = jittered_directions(300.0, 55.0, 8.0, maps, 1);
  ProbabilityOptions o;
  o.terrain = gl ? TerrainOcclusion::OpenGL : TerrainOcclusion::Sweep;
  for (auto _ : state) benchmark::DoNotOptimize(snow_probability(scene, dirs, o).ground.data());
  state.counters["s/map"] =
      benchmark::Counter(static_cast<double>(maps) * state.iterations(),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["peak_MiB"] = drift::bench::peak_resident_mib();
}
// Ground only; args: size, maps, 0 = horizon sweep / 1 = OSMesa.
BENCHMARK(BM_SnowProbability)
    ->Args({1024, 16, 0})
    ->Args({1024, 16, 1})
    ->Args({4096, 16, 0})
    ->Args({4096, 2, 1})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

// Args: grid size, coarse levels (StabiliseOptions::coarse_levels; 0: the
// default, the passes and their shortcut alone), 1 = the one-step solver
// (StabiliseOptions::direct, snow/stabilise_direct.h) instead of the passes.
void BM_StabiliseGround(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  StabiliseOptions options;
  options.coarse_levels = static_cast<int>(state.range(1));
  options.direct = state.range(2) != 0;
  const SnowScene scene = make_snow_scene(mountains(n), {}, 0.0);
  const auto p = snow_probability(scene, jittered_directions(300.0, 55.0, 8.0, 4, 1)).ground;
  StabiliseReport r;
  double excess = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    drift::terrain::Grid<double> snow(n, n, 0.0);
    for (std::size_t i = 0; i < snow.size(); ++i) snow.values()[i] = p.values()[i] * 0.5;
    state.ResumeTiming();
    r = stabilise_grid(scene.ground, snow, 1.0, 1.0, options);
    state.PauseTiming();
    excess = max_repose_excess(scene.ground, snow, 1.0, 1.0, 40.0, StabiliseOptions{}.tolerance);
    state.ResumeTiming();
  }
  state.counters["passes"] = r.iterations;  // on the grid itself
  if (r.level_passes.size() > 1) state.counters["coarsest_passes"] = r.level_passes.front();
  state.counters["max_excess_m"] = excess;  // slopes above repose left (1 m cells)
  state.counters["peak_MiB"] = drift::bench::peak_resident_mib();
}
BENCHMARK(BM_StabiliseGround)
    ->ArgNames({"n", "coarse_levels", "direct"})
    ->ArgsProduct({{256, 1024, 4096}, {0, 1}, {0}})
    ->ArgsProduct({{256, 1024, 4096, 8192}, {0}, {1}})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

// The one-step solver's state against the passes' (the default's) on the
// same field as BM_StabiliseGround: RMS of the snow (m), the share of cells
// off by more than 10 cm, the ground covered (snow over 1 mm) by each, and
// the CPU of each call. The passes' state is what the one-step solver must
// reach within docs/snowfall.md's tolerance to be the default. Args: grid
// size, the one-step solver's layers (StabiliseOptions::direct_layers).
void BM_DirectAgainstPasses(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0)), layers = static_cast<int>(state.range(1));
  const SnowScene scene = make_snow_scene(mountains(n), {}, 0.0);
  const auto p = snow_probability(scene, jittered_directions(300.0, 55.0, 8.0, 4, 1)).ground;
  drift::terrain::Grid<double> start(n, n, 0.0);
  for (std::size_t i = 0; i < start.size(); ++i) start.values()[i] = p.values()[i] * 0.5;
  auto run = [&](bool direct, double& seconds) {
    StabiliseOptions options;
    options.direct = direct;
    options.direct_layers = layers;
    drift::terrain::Grid<double> snow = start;
    const auto t0 = std::chrono::steady_clock::now();
    stabilise_grid(scene.ground, snow, 1.0, 1.0, options);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return snow;
  };
  double t_passes = 0.0, t_direct = 0.0;
  drift::terrain::Grid<double> passes(1, 1, 0.0), direct(1, 1, 0.0);
  for (auto _ : state) {
    passes = run(false, t_passes);
    direct = run(true, t_direct);
  }
  double sq = 0.0, off = 0.0, cover_p = 0.0, cover_d = 0.0, mass_p = 0.0, mass_d = 0.0;
  for (std::size_t i = 0; i < passes.size(); ++i) {
    const double a = passes.values()[i], b = direct.values()[i];
    sq += (a - b) * (a - b), off += std::abs(a - b) > 0.1;
    cover_p += a > 1e-3, cover_d += b > 1e-3, mass_p += a, mass_d += b;
  }
  const double cells = static_cast<double>(passes.size());
  state.counters["rms_m"] = std::sqrt(sq / cells);
  state.counters["off_10cm_pct"] = 100.0 * off / cells;
  state.counters["cover_passes_pct"] = 100.0 * cover_p / cells;
  state.counters["cover_direct_pct"] = 100.0 * cover_d / cells;
  state.counters["mass_rel"] = (mass_d - mass_p) / mass_p;
  state.counters["s_passes"] = t_passes;
  state.counters["s_direct"] = t_direct;
  state.counters["max_excess_m"] = max_repose_excess(scene.ground, direct, 1.0, 1.0, 40.0, 0.0);
}
BENCHMARK(BM_DirectAgainstPasses)
    ->ArgNames({"n", "layers"})
    ->ArgsProduct({{256, 1024, 2048}, {1, 4, 16}})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

void BM_SnowfallWithObjects(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto ground = mountains(n);
  const auto objs = objects(n);
  std::size_t triangles = 0;
  for (const auto& o : objs) triangles += o.mesh.triangle_count();
  // 25 h from the west-north-west at 55 degrees: the defaults' 16 maps and 2 cm/h.
  SnowfallOptions o;
  o.azimuth_deg = 300.0;
  o.elevation_deg = 55.0;
  o.spread_deg = 8.0;
  o.hours = 25.0;
  o.mesh_max_edge = 0.0;
  SnowfallResult r;
  for (auto _ : state) r = simulate_snowfall(ground, objs, o);
  state.counters["triangles"] = static_cast<double>(triangles);
  state.counters["ground_passes"] = r.ground_iterations;
  state.counters["peak_MiB"] = drift::bench::peak_resident_mib();
}
BENCHMARK(BM_SnowfallWithObjects)
    ->Arg(1024)
    ->Arg(4096)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
