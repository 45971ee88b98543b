// Voxel soil (paper 004) in the thesis's benchmark scene (sec. 4.2, figs.
// 53-57): a block pushing soil, 4 force-propagation iterations, dry sand
// phi = 25, c = 0, gamma = 2. Steps per second and peak memory at 32^3 to
// 256^3 (fig. 54), and time per step against propagation iterations at 72^3
// (fig. 57). The thesis: t = 2.4e-5 ms x voxels + 4.3 ms per frame on an
// R9 270 GPU; t = 1.17 alpha + 8.95 ms at 72^3.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "terrain/soil/soil_surface.h"
#include "tests/bench/peak_memory.h"
#include "tests/soil/soil_fixtures.h"

namespace {

using namespace drift::soil;

SoilOptions thesis_options(int alpha) {
  SoilOptions o;
  o.propagation_iterations = alpha;
  o.soil = {"thesis", 25.0, 0.0, 2.0, 0.0};
  return o;
}

// Warm-up steps put the block into the soil first, so the timed steps push.
void run_push(benchmark::State& state, int n, int alpha) {
  drift::bench::reset_peak_resident();
  SoilSimulation sim = make_simulation(fixtures::push_scenario(n, thesis_options(alpha)));
  sim.run(20);
  for (auto _ : state) sim.step();
  state.counters["steps/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
  state.counters["voxels/s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * n * n * n, benchmark::Counter::kIsRate);
  state.counters["peak_MiB"] = drift::bench::peak_resident_mib();
}

void BM_SoilPushResolution(benchmark::State& state) {
  run_push(state, static_cast<int>(state.range(0)), 4);
}
BENCHMARK(BM_SoilPushResolution)
    ->Arg(32)
    ->Arg(64)
    ->Arg(72)
    ->Arg(128)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The push of the thesis's benchmark on an n^3 grid, 20 steps in.
SoilSimulation pushing(int n) {
  SoilSimulation sim = make_simulation(fixtures::push_scenario(n, thesis_options(4)));
  sim.run(20);
  return sim;
}

// Step plus surface extraction (the thesis's frame: simulate and mesh), at
// 64^3: the thesis's 60 frames a second is 16.7 ms. Args: n, threads,
// incremental (SurfaceExtractor, issue 33 item 1) or a full soil_surface a
// frame. Process CPU time (all threads) and wall time.
void BM_SoilStepAndSurface(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(state.range(1)));
  SoilSimulation sim = pushing(static_cast<int>(state.range(0)));
  const bool incremental = state.range(2) != 0;
  SurfaceExtractor extractor;
  if (incremental) extractor.extract(sim.state());
  std::size_t triangles = 0;
  for (auto _ : state) {
    sim.step();
    triangles = (incremental ? extractor.extract(sim.state()) : soil_surface(sim.state(), {}))
                    .triangle_count();
  }
  state.counters["frames/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
  state.counters["triangles"] = static_cast<double>(triangles);
}
BENCHMARK(BM_SoilStepAndSurface)
    ->ArgNames({"n", "threads", "incremental"})
    ->Args({64, 1, 0})
    ->Args({64, 1, 1})
    ->Args({64, 2, 0})
    ->Args({64, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// The step alone on 1 or 2 threads (process CPU and wall).
void BM_SoilStep(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(state.range(1)));
  SoilSimulation sim = pushing(static_cast<int>(state.range(0)));
  for (auto _ : state) sim.step();
}
BENCHMARK(BM_SoilStep)
    ->ArgNames({"n", "threads"})
    ->Args({64, 1})
    ->Args({64, 2})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// The surface alone (the ridge fix's density, then the mesh) and the density
// alone, of the same push.
void BM_SoilSurface(benchmark::State& state) {
  const SoilSimulation sim = pushing(static_cast<int>(state.range(0)));
  const bool mesh = state.range(1) != 0;
  for (auto _ : state) {
    if (mesh)
      benchmark::DoNotOptimize(soil_surface(sim.state(), {}));
    else
      benchmark::DoNotOptimize(surface_density(sim.state(), {}));
  }
}
BENCHMARK(BM_SoilSurface)
    ->ArgNames({"n", "mesh"})
    ->Args({64, 0})
    ->Args({64, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_SoilPushIterations(benchmark::State& state) {
  run_push(state, 72, static_cast<int>(state.range(0)));
}
BENCHMARK(BM_SoilPushIterations)
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
