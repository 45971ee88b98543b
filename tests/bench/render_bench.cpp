// Renderer throughput on the default scene (Yarigatake, imported to UTM) at
// 1280x720, 64 spp: wall time, samples and rays per second of the whole path
// tracer next to Embree's raw throughput on the same scene (its camera rays,
// and the path tracer's own rays replayed, intersection only); with peak
// memory. And the cost of the terrain
// scene itself for large DEMs (4096^2 and 8192^2): build time and bytes per
// DEM vertex, resident and at the peak of the build.
//
// Needs out/yarigatake_utm.tif (run `make -C data/scenes default` or
// `drift import data/yarigatake_gsi_dem10b_jgd2000.tif -o out/yarigatake_utm.tif`).
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <vector>

#include "pipeline/scene_file.h"
#include "render/camera_setup.h"
#include "render/renderer.h"
#include "tests/bench/peak_memory.h"

namespace {

using namespace drift;

struct Fixture {
  pipeline::SceneFile scene;
  std::unique_ptr<render::TerrainScene> embree;  // TerrainGeometry::Auto (the grid here)
  // The same terrain as each geometry by name, for the benchmarks' geometry
  // argument: 0 the height field (render/height_field.h, the default from
  // 4096^2 cells), 1 Embree's grid geometry over float3 vertices.
  std::unique_ptr<render::TerrainScene> heights;
  std::unique_ptr<render::TerrainScene> grid;
  render::Camera camera;
};

// CPU seconds of the whole process, every thread (user + system): on a
// shared machine rays per CPU second compare runs that wall time cannot.
double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  const auto seconds = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  return seconds(u.ru_utime) + seconds(u.ru_stime);
}

Fixture& fixture() {
  static Fixture f = [] {
    Fixture x;
    x.scene = pipeline::read_scene_file(std::filesystem::path(DRIFT_SOURCE_DIR) /
                                        "data/scenes/default.toml");
    x.scene.terrain_raster = std::filesystem::path(DRIFT_SOURCE_DIR) / "out/yarigatake_utm.tif";
    pipeline::load_scene_terrain(x.scene);
    x.embree = std::make_unique<render::TerrainScene>(x.scene.input);
    x.heights =
        std::make_unique<render::TerrainScene>(x.scene.input, render::TerrainGeometry::HeightField);
    x.grid = std::make_unique<render::TerrainScene>(x.scene.input, render::TerrainGeometry::Grid);
    x.camera = render::default_camera(*x.embree);
    x.scene.settings.width = 1280;
    x.scene.settings.height = 720;
    x.scene.settings.samples_per_pixel = 64;
    return x;
  }();
  return f;
}

// A synthetic DEM of n x n cells of 10 m: ridges of several wavelengths (the
// values do not matter to the memory, only that Embree sees real relief).
terrain::HeightField synthetic_dem(int n) {
  terrain::HeightField dem(n, n, 0.0f, terrain::local_georeference(10.0));
  tbb::parallel_for(0, n, [&](int row) {
    for (int x = 0; x < n; ++x) {
      float z = 0.0f, amplitude = 400.0f, k = 0.003f;
      for (int octave = 0; octave < 5; ++octave, amplitude *= 0.45f, k *= 2.1f) {
        z += amplitude * std::abs(std::sin(k * x + 1.7f * octave) * std::cos(k * row * 0.8f));
      }
      dem(x, row) = z;
    }
  });
  return dem;
}

// Building the Embree scene of a large DEM: seconds, and bytes per DEM vertex
// resident after the build and at its peak (the DEM itself, 4 B a vertex,
// held by the caller, is not counted). Second argument 0: the height-field
// geometry (4 B of heights and the min-max tree), 1: Embree's grid geometry
// (12 B of float3 vertices plus Embree's grid data, ~32 B).
void BM_TerrainSceneBuild(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto geometry =
      state.range(1) ? render::TerrainGeometry::Grid : render::TerrainGeometry::HeightField;
  render::SceneInput input;
  input.terrain = synthetic_dem(n);
  const double vertices = static_cast<double>(n) * n;
  double resident = 0.0, peak = 0.0, seconds = 0.0;
  for (auto _ : state) {
    const std::uint64_t before = bench::resident_bytes();
    bench::reset_peak_resident();
    const auto start = std::chrono::steady_clock::now();
    render::TerrainScene scene(input, geometry);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    resident = static_cast<double>(bench::resident_bytes() - before);
    peak = static_cast<double>(bench::peak_resident_bytes() - before);
    benchmark::DoNotOptimize(scene.top());
  }
  state.counters["build_s"] = seconds;
  state.counters["B/vertex"] = resident / vertices;
  state.counters["peak_B/vertex"] = peak / vertices;
  state.counters["Mvertices/s"] = vertices / seconds / 1e6;
}
BENCHMARK(BM_TerrainSceneBuild)
    ->Args({4096, 0})
    ->Args({4096, 1})
    ->Args({8192, 0})
    ->Args({8192, 1})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

// Rays 0 .. n - 1 traced by trace(i) (true on a hit) over TBB's threads;
// the hits, and the CPU seconds of the whole process added to `cpu`.
template <class Trace>
std::uint64_t trace_all(std::size_t n, const Trace& trace, double& cpu) {
  std::atomic<std::uint64_t> hits{0};
  const double start = process_cpu_seconds();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      std::uint64_t local = 0;
                      for (std::size_t i = r.begin(); i != r.end(); ++i) local += trace(i);
                      hits += local;
                    });
  cpu += process_cpu_seconds() - start;
  return hits;
}

void trace_frames(benchmark::State& state, const render::SceneInput& input, int spp = 64) {
  Fixture& f = fixture();
  render::RenderSettings settings = f.scene.settings;
  settings.samples_per_pixel = spp;
  render::RenderStats stats;
  double cpu = 0.0;
  for (auto _ : state) {
    const double start = process_cpu_seconds();
    auto img = render::render_image(*f.embree, input, f.camera, settings, no_progress, &stats);
    cpu += process_cpu_seconds() - start;
    benchmark::DoNotOptimize(img.pixels.data());
  }
  state.counters["rays/cpu_s"] = static_cast<double>(stats.rays) * state.iterations() / cpu;
  state.counters["rays/s"] = benchmark::Counter(
      static_cast<double>(stats.rays) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["samples/s"] = benchmark::Counter(
      static_cast<double>(stats.camera_rays) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["rays/sample"] = static_cast<double>(stats.rays) / stats.camera_rays;
  state.counters["peak_MiB"] = bench::peak_resident_mib();
}

// Argument: samples a pixel. At 4 (kRecordedSpp) the path tracer traces
// exactly the rays BM_RawEmbreeSameRays replays: its rays/cpu_s over theirs
// (grid geometry, argument 1) is the share of the frame Embree's traversal
// takes.
void BM_PathTracer(benchmark::State& state) {
  trace_frames(state, fixture().scene.input, static_cast<int>(state.range(0)));
}
BENCHMARK(BM_PathTracer)->Arg(64)->Arg(4)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// A small default frame (320x180, 32 spp) on one thread through each terrain
// geometry: argument 0 the height field, 1 Embree's grid (issue 36: 9.3 s
// against 6.4 s before the height field's leaves skipped the cells a ray does
// not cross). CPU seconds, comparable on a loaded machine.
void BM_SmallFrame(benchmark::State& state) {
  Fixture& f = fixture();
  const render::TerrainScene& scene = state.range(0) ? *f.grid : *f.heights;
  render::RenderSettings settings = f.scene.settings;
  settings.width = 320;
  settings.height = 180;
  settings.samples_per_pixel = 32;
  const render::Camera camera = render::default_camera(scene);
  tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  double cpu = 0.0;
  for (auto _ : state) {
    const double start = process_cpu_seconds();
    auto img = render::render_image(scene, f.scene.input, camera, settings, no_progress);
    cpu += process_cpu_seconds() - start;
    benchmark::DoNotOptimize(img.pixels.data());
  }
  state.counters["cpu_s"] = cpu / static_cast<double>(state.iterations());
}
BENCHMARK(BM_SmallFrame)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// The same frame with light shafts (16 shadow tests per camera ray).
void BM_PathTracerLightShafts(benchmark::State& state) {
  render::SceneInput input = fixture().scene.input;
  input.sky.light_shafts = true;
  trace_frames(state, input);
}
BENCHMARK(BM_PathTracerLightShafts)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// Raw Embree: the same 1280x720x64 camera rays, generated before timing, traced
// with TerrainScene::hits (rtcIntersect1 alone, nothing shaded) over the same
// TBB threads: the most coherent rays of the frame.
void BM_RawEmbreeCameraRays(benchmark::State& state) {
  Fixture& f = fixture();
  const render::TerrainScene& scene = state.range(0) ? *f.grid : *f.heights;
  const auto& rs = f.scene.settings;
  const render::CameraRays pinhole =
      render::make_camera_rays(*f.embree, f.camera, rs.width, rs.height);
  const int spp = rs.samples_per_pixel;
  std::vector<Eigen::Vector3f> dirs(static_cast<std::size_t>(rs.width) * rs.height * spp);
  for (int y = 0; y < rs.height; ++y)
    for (int x = 0; x < rs.width; ++x)
      for (int s = 0; s < spp; ++s)
        dirs[(static_cast<std::size_t>(y) * rs.width + x) * spp + s] =
            pinhole.direction(x + (s + 0.5f) / spp, y + 0.5f);
  std::uint64_t hits = 0;
  double cpu = 0.0;
  for (auto _ : state) {
    hits += trace_all(
        dirs.size(), [&](std::size_t i) { return scene.hits(pinhole.eye, dirs[i]); }, cpu);
  }
  state.counters["rays/s"] = benchmark::Counter(
      static_cast<double>(dirs.size()) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["rays/cpu_s"] = static_cast<double>(dirs.size()) * state.iterations() / cpu;
  state.counters["hit_fraction"] =
      static_cast<double>(hits) / (static_cast<double>(dirs.size()) * state.iterations());
  state.counters["peak_MiB"] = bench::peak_resident_mib();
}
// Argument 0: the height-field geometry; 1: Embree's grid geometry.
BENCHMARK(BM_RawEmbreeCameraRays)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

// The path tracer's own rays (camera, bounce, shadow and cloud rays, in the
// order each thread traced them), recorded once from the default frame at
// kRecordedSpp samples a pixel (the mix of rays is BM_PathTracer's; 64 spp
// would take 5 GB).
constexpr int kRecordedSpp = 4;

struct RecordedRay {
  Eigen::Vector3f origin, dir;
  float max_distance;
  bool shadow;
};

class Recorder final : public render::RayRecorder {
 public:
  void traced(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float max_distance,
              bool shadow) override {
    rays_.local().push_back({origin, dir, max_distance, shadow});
  }
  std::vector<RecordedRay> take() {
    std::vector<RecordedRay> all;
    for (auto& part : rays_) all.insert(all.end(), part.begin(), part.end());
    return all;
  }

 private:
  tbb::enumerable_thread_specific<std::vector<RecordedRay>> rays_;
};

std::vector<RecordedRay> record_path_tracer_rays() {
  Fixture& f = fixture();
  render::RenderSettings settings = f.scene.settings;
  settings.samples_per_pixel = kRecordedSpp;
  Recorder recorder;
  f.embree->record_rays(&recorder);
  render::render_image(*f.embree, f.scene.input, f.camera, settings, no_progress);
  f.embree->record_rays(nullptr);
  return recorder.take();
}

// Raw Embree on the path tracer's own rays: rtcIntersect1 (TerrainScene::hits)
// or rtcOccluded1 (TerrainScene::occluded), nothing shaded, over the same TBB
// threads. BM_PathTracer's rays/s over this one's is how much of the frame's
// time goes to Embree's traversal.
void BM_RawEmbreeSameRays(benchmark::State& state) {
  static const std::vector<RecordedRay> rays = record_path_tracer_rays();
  const render::TerrainScene& scene = state.range(0) ? *fixture().grid : *fixture().heights;
  std::uint64_t hits = 0;
  double cpu = 0.0;
  const auto trace = [&](std::size_t i) {
    const RecordedRay& ray = rays[i];
    return ray.shadow ? scene.occluded(ray.origin, ray.dir, ray.max_distance)
                      : scene.hits(ray.origin, ray.dir);
  };
  for (auto _ : state) hits += trace_all(rays.size(), trace, cpu);
  const auto shadow =
      std::count_if(rays.begin(), rays.end(), [](const auto& r) { return r.shadow; });
  state.counters["rays/s"] = benchmark::Counter(
      static_cast<double>(rays.size()) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["rays/cpu_s"] = static_cast<double>(rays.size()) * state.iterations() / cpu;
  state.counters["rays"] = static_cast<double>(rays.size());
  state.counters["shadow_fraction"] =
      static_cast<double>(shadow) / static_cast<double>(rays.size());
  state.counters["hit_fraction"] =
      static_cast<double>(hits) / (static_cast<double>(rays.size()) * state.iterations());
}
// Argument 0: the height-field geometry; 1: Embree's grid geometry.
BENCHMARK(BM_RawEmbreeSameRays)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
