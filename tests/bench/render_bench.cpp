// Renderer throughput on the default scene (Yarigatake, imported to UTM) at
// 640x360, 16 spp: rays per second of the whole path tracer next to Embree's raw
// throughput on the same scene (the same camera rays, intersection only), and
// their ratio; with peak memory.
//
// Needs out/yarigatake_utm.tif (run `make -C data/scenes default` or
// `drift import data/yarigatake_gsi_dem10b_jgd2000.tif -o out/yarigatake_utm.tif`).
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <vector>

#include "pipeline/scene_file.h"
#include "render/renderer.h"
#include "tests/bench/peak_memory.h"

namespace {

using namespace drift;

struct Fixture {
  pipeline::SceneFile scene;
  std::unique_ptr<render::TerrainScene> embree;
  render::Camera camera;
};

Fixture& fixture() {
  static Fixture f = [] {
    Fixture x;
    x.scene = pipeline::read_scene_file(std::filesystem::path(DRIFT_SOURCE_DIR) /
                                        "data/scenes/default.toml");
    x.scene.terrain_raster = std::filesystem::path(DRIFT_SOURCE_DIR) / "out/yarigatake_utm.tif";
    pipeline::load_scene_terrain(x.scene);
    x.embree = std::make_unique<render::TerrainScene>(x.scene.input);
    x.camera = render::default_camera(*x.embree);
    x.scene.settings.width = 640;
    x.scene.settings.height = 360;
    x.scene.settings.samples_per_pixel = 16;
    return x;
  }();
  return f;
}

void trace_frames(benchmark::State& state, const render::SceneInput& input) {
  Fixture& f = fixture();
  render::RenderStats stats;
  for (auto _ : state) {
    auto img =
        render::render_image(*f.embree, input, f.camera, f.scene.settings, no_progress, &stats);
    benchmark::DoNotOptimize(img.pixels.data());
  }
  state.counters["rays/s"] = benchmark::Counter(
      static_cast<double>(stats.rays) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["samples/s"] = benchmark::Counter(
      static_cast<double>(stats.camera_rays) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["rays/sample"] = static_cast<double>(stats.rays) / stats.camera_rays;
  state.counters["peak_MiB"] = bench::peak_resident_mib();
}

void BM_PathTracer(benchmark::State& state) { trace_frames(state, fixture().scene.input); }
BENCHMARK(BM_PathTracer)->Unit(benchmark::kSecond)->UseRealTime()->MinTime(2.0);

// The same frame with light shafts (16 shadow tests per camera ray).
void BM_PathTracerLightShafts(benchmark::State& state) {
  render::SceneInput input = fixture().scene.input;
  input.sky.light_shafts = true;
  trace_frames(state, input);
}
BENCHMARK(BM_PathTracerLightShafts)->Unit(benchmark::kSecond)->UseRealTime()->MinTime(2.0);

// Raw Embree: the same 640x360x16 camera rays, generated before timing, traced
// with TerrainScene::intersect (rtcIntersect1 plus the hit record) over the same
// TBB threads: the ceiling the path tracer's camera rays could reach.
void BM_RawEmbreeCameraRays(benchmark::State& state) {
  Fixture& f = fixture();
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
  std::atomic<std::uint64_t> hits{0};
  for (auto _ : state) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, dirs.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        std::uint64_t local = 0;
                        render::Hit hit;
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          local += f.embree->intersect(pinhole.eye, dirs[i], hit);
                        }
                        hits += local;
                      });
  }
  state.counters["rays/s"] = benchmark::Counter(
      static_cast<double>(dirs.size()) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["hit_fraction"] =
      static_cast<double>(hits) / (static_cast<double>(dirs.size()) * state.iterations());
  state.counters["peak_MiB"] = bench::peak_resident_mib();
}
BENCHMARK(BM_RawEmbreeCameraRays)->Unit(benchmark::kSecond)->UseRealTime()->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
