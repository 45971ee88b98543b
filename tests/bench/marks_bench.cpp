// Marks (paper 000) per step on flat sand with 1 cm cells, at the paper's
// 256 x 256 and at 1024 x 1024: a 10k-triangle shoe walked along pressed 1 cm
// in, and a 20 cm ball dragged 10 cells a step placed without sweep, in 10
// sub-steps and swept (the paper's table 1: 0.022, 0.22, 0.027 s a step on a
// Pentium 4 with a GeForce4). Also the object's bottom rendered by the CPU
// z-buffer against OSMesa at growing windows. Counters: steps/s, peak memory.
// docs/marks.md, Performance, tabulates them beside the paper's table 1; the
// "Time" column is wall time, "CPU" one thread's (compare those on a shared
// machine).
#include <benchmark/benchmark.h>

#include <memory>

#include "terrain/marks/marks.h"
#include "terrain/mesh_io.h"
#include "tests/bench/peak_memory.h"

namespace {

using namespace drift::marks;
constexpr double kCell = 0.01;

drift::terrain::Mesh object(const char* name) {
  return drift::terrain::read_obj(std::string(DRIFT_SOURCE_DIR "/data/objects/") + name);
}

MaterialField sand() {
  MaterialField m;
  m.table = {*material_preset("sand")};
  return m;
}

// Moves `mesh` along row n/2 by `stride` cells a step from column 40, at
// height z above the 1 m ground; a new field when it nears the far edge.
void run_track(benchmark::State& state, const char* mesh, double z, int stride, Motion motion,
               int resolution = 1) {
  const int n = static_cast<int>(state.range(0));
  const drift::terrain::HeightField ground(n, n, 1.0f, drift::terrain::local_georeference(kCell));
  const ObjectShape shape = ObjectShape::of(object(mesh));
  MarkObject o;
  o.motion = motion;
  o.resolution = resolution;
  std::unique_ptr<MarksSimulation> sim;
  Pose from;
  int col = 0;
  drift::bench::reset_peak_resident();
  for (auto _ : state) {
    if (!sim || col + stride > n - 40) {
      state.PauseTiming();
      sim = std::make_unique<MarksSimulation>(ground, sand(), MarksOptions{});
      col = 40;
      from = {sim->frame().to_world(col, n / 2, 1.0 + z), Eigen::Quaterniond::Identity()};
      sim->move(shape, o, from, from, true);
      sim->end_step();
      state.ResumeTiming();
    }
    col += stride;
    const Pose to{sim->frame().to_world(col, n / 2, 1.0 + z), Eigen::Quaterniond::Identity()};
    sim->move(shape, o, from, to, false);
    sim->end_step();
    from = to;
  }
  state.counters["steps/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["peak_MiB"] = drift::bench::peak_resident_mib();
}

void BM_MarksShoeWalk(benchmark::State& state) {
  run_track(state, "shoe.obj", -0.01, 1, Motion::Sweep);
}
BENCHMARK(BM_MarksShoeWalk)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

void BM_MarksBallDrag(benchmark::State& state) {
  run_track(state, "ball.obj", 0.1 - 0.03, 10, static_cast<Motion>(state.range(1)));
}
BENCHMARK(BM_MarksBallDrag)
    ->ArgNames({"n", "motion(0 sweep,1 substeps,2 place)"})
    ->ArgsProduct({{256, 1024}, {2, 1, 0}})
    ->Unit(benchmark::kMillisecond);

// Paper 000, 3.6 and fig. 12: the swept ball worked at half and quarter
// resolution (the paper: 25 against 16 steps/s at half resolution).
void BM_MarksBallDragCoarse(benchmark::State& state) {
  run_track(state, "ball.obj", 0.1 - 0.03, 10, Motion::Sweep, static_cast<int>(state.range(1)));
}
BENCHMARK(BM_MarksBallDragCoarse)
    ->ArgNames({"n", "level"})
    ->ArgsProduct({{256, 1024}, {1, 2, 4}})
    ->Unit(benchmark::kMillisecond);

// The bottom of a ball of `radius` cells by each renderer.
void BM_MarksBottom(benchmark::State& state) {
  const double r = static_cast<double>(state.range(0));
  const auto kind = state.range(1) ? BottomRenderer::OpenGL : BottomRenderer::Cpu;
  drift::terrain::Mesh m = object("ball.obj");
  for (auto& p : m.positions) p *= static_cast<float>(r / 0.1);
  const ObjectShape shape = ObjectShape::of(std::move(m));
  const GridFrame frame{0.5, -0.5, 1.0, 1.0};
  const CellTriangles tris = posed_triangles(
      shape, {frame.to_world(r + 4, r + 4, 0.0), Eigen::Quaterniond::Identity()}, frame);
  BottomMap b;
  b.window = footprint_window(tris, 2, 100000, 100000);
  auto renderer = make_bottom_rasteriser(kind);
  for (auto _ : state) {
    renderer->render(tris, b);
    benchmark::DoNotOptimize(b.z.data());
  }
  state.counters["cells"] = static_cast<double>(b.z.size());
  state.counters["renders/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MarksBottom)
    ->ArgNames({"radius", "opengl"})
    ->ArgsProduct({{8, 32, 128, 512}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
