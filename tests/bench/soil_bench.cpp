// Voxel soil (paper 004) in the thesis's benchmark scene (sec. 4.2, figs.
// 53-57): a block pushing soil, 4 force-propagation iterations, dry sand
// phi = 25, c = 0, gamma = 2. Steps per second and peak memory at 32^3 to
// 256^3 (fig. 54), and time per step against propagation iterations at 72^3
// (fig. 57). The thesis: t = 2.4e-5 ms x voxels + 4.3 ms per frame on an
// R9 270 GPU; t = 1.17 alpha + 8.95 ms at 72^3.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "terrain/soil/soil_surface.h"
#include "terrain/soil/solid_mesh.h"
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

// A fixed stretch of the push: the 120 frames (step plus incremental
// surface) after the first 20 steps, the same work on every run (the
// benchmarks above run as many steps as their time allows, and the push ends
// after 154 steps, so their mean mixes pushing and settling). For comparing
// binaries: CPU time (of 120 frames) and, under load, `perf stat -e
// instructions`.
void BM_SoilPushFrames(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
  for (auto _ : state) {
    state.PauseTiming();
    SoilSimulation sim = pushing(64);
    SurfaceExtractor extractor;
    extractor.extract(sim.state());
    state.ResumeTiming();
    for (int k = 0; k < 120; ++k) {
      sim.step();
      benchmark::DoNotOptimize(extractor.extract(sim.state()).triangle_count());
    }
  }
}
BENCHMARK(BM_SoilPushFrames)
    ->Iterations(3)
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

// The collision field a step rebuilds for one moving body (psi = the static
// field, plus the body's coverage; SoilSimulation::rebuild_collision_field)
// at 64^3, for the push's blade: 0 axis-aligned (the exact cuboid share), 1
// turned 20 degrees about z, 2 a closed box mesh of the same size turned
// the same (both by refined_share, issue 33's exact coverage), 3 a turned
// cylinder (refined, with an error bound).
void BM_SoilBodyCoverage(benchmark::State& state) {
  const SoilScenario sc = fixtures::push_scenario(64, thesis_options(4));
  const drift::terrain::Grid3Shape& g = sc.shape;
  RigidObject body = sc.bodies.front();
  const Eigen::Vector3d h = body.primitives.front().size;
  const int kind = static_cast<int>(state.range(0));
  if (kind > 0)
    for (Keyframe& k : body.path)
      k.orientation =
          Eigen::Quaterniond(Eigen::AngleAxisd(20.0 * M_PI / 180, Eigen::Vector3d::UnitZ()));
  if (kind == 2) {
    drift::terrain::Mesh m;
    for (int c = 0; c < 8; ++c)
      m.positions.emplace_back(c & 1 ? h.x() : -h.x(), c & 2 ? h.y() : -h.y(),
                               c & 4 ? h.z() : -h.z());
    // Outward, counter-clockwise: two triangles a face.
    m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                   {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    body.mesh = std::make_shared<SolidMesh>(m, 0.5 * g.voxel_size, "box");
    body.primitives.clear();
  }
  if (kind == 3) body.primitives.front().kind = PrimitiveKind::Cylinder;
  const std::vector<float> psi_static(g.count(), 0.0f);
  std::vector<float> psi;
  double t = 0;
  for (auto _ : state) {
    psi = psi_static;
    add_coverage(placed(body, t), g, psi);
    t += 1.0 / 60;  // a step of the push
    benchmark::DoNotOptimize(psi.data());
  }
}
BENCHMARK(BM_SoilBodyCoverage)
    ->ArgName("kind")
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Arg(3)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
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
