#include "render/renderer.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "render/camera_setup.h"
#include "render/color.h"
#include "render/mattes.h"
#include "render/path_tracer.h"
#include "render/random.h"
#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::render {

namespace {

using Eigen::Vector3f;

// Running mean and variance of a pixel's sample luminances (Welford 1962),
// for adaptive sampling.
struct PixelNoise {
  int n = 0;
  double mean = 0.0, m2 = 0.0;
  void add(double v) {
    ++n;
    const double d = v - mean;
    mean += d / n;
    m2 += d * (v - mean);
  }
  // Standard error of the mean over the mean. Luminances below kDark (render
  // units; black after the tone curve at exposure 0) are judged against kDark,
  // so that dark pixels do not sample forever for an invisible relative error.
  double relative_error() const {
    constexpr double kDark = 0.01;
    if (n < 2) return 1e30;
    return std::sqrt(m2 / (n - 1) / n) / std::max(mean, kDark);
  }
};

}  // namespace

namespace {

void check_settings(const RenderSettings& settings, int row_begin, int row_end) {
  if (settings.width < 1 || settings.height < 1 || settings.samples_per_pixel < 1 ||
      settings.max_depth < 1 || settings.min_samples < 1) {
    throw Error(
        "render size, samples per pixel, minimum samples and max depth must all be at least 1");
  }
  if (!(settings.noise_target >= 0.0f)) throw Error("the noise target must be 0 (off) or more");
  if (row_begin < 0 || row_begin >= row_end || row_end > settings.height) {
    throw Error("rows [" + std::to_string(row_begin) + ", " + std::to_string(row_end) +
                ") are not inside the " + std::to_string(settings.height) + "-row frame");
  }
}

// What a render writes besides radiance: the first hit's AOVs under the
// names compositors look for (Z, N, P) and the mattes.
struct FrameLayout {
  int coverage_count = 0;
  bool adaptive = false;
  const FrameMattes* mattes = nullptr;
  Eigen::Vector3d local_to_world{0, 0, 0};  // P's frame: CRS less the header's worldOrigin
};

// The image's channels, in the order store_pixel writes them.
std::vector<std::string> image_channels(const TerrainScene& scene, const FrameLayout& layout) {
  std::vector<std::string> channels = {"R",   "G",   "B",        "Z",        "N.X",
                                       "N.Y", "N.Z", "albedo.R", "albedo.G", "albedo.B",
                                       "P.X", "P.Y", "P.Z"};
  for (const std::string& name : scene.coverage_names()) channels.push_back("coverage." + name);
  channels.emplace_back("mask.sky");
  if (layout.adaptive) channels.emplace_back("samples");
  for (const CryptomatteLayer* layer : {&layout.mattes->material(), &layout.mattes->object()})
    for (const std::string& c : layer->channels()) channels.push_back(c);
  return channels;
}

// A pixel's sums over its samples.
struct PixelSums {
  PixelSample sum;
  int hits = 0;                       // samples whose camera ray met something
  Eigen::Vector3d position{0, 0, 0};  // of the hits, local frame
  double depth = 0.0;                 // likewise
  FrameMattes::Weights mattes;
};

// The samples of one pixel: samples_per_pixel, or fewer once the noise target
// is met. Returns their sums and sets `taken`.
PixelSums sample_pixel(const PathTracer& tracer, const RenderSettings& settings, int x, int y,
                       const FrameLayout& layout, int& taken, std::uint64_t& rays) {
  PixelSums sums;
  PixelSample& sum = sums.sum;
  sums.mattes = layout.mattes->weights();
  PixelNoise noise;
  const std::uint64_t pixel = static_cast<std::uint64_t>(y) * settings.width + x;
  taken = 0;
  // Samples in batches of PathTracer::kCoherentSamples (8), their camera rays
  // traced together; adaptive sampling decides after every 8, at a batch's
  // end, so a batch is never cut short.
  constexpr int kBatch = PathTracer::kCoherentSamples;
  static_assert(kBatch == 8, "the adaptive decision below is every 8 samples");
  std::array<PixelSample, kBatch> batch;
  int in_batch = 0, next = 0;
  while (taken < settings.samples_per_pixel) {
    if (next == in_batch) {
      in_batch = std::min(kBatch, settings.samples_per_pixel - taken);
      const auto stream = [&](int i) {
        return SampleStream(settings.seed, pixel, static_cast<std::uint64_t>(taken + i));
      };
      std::array<SampleStream, kBatch> rngs{stream(0), stream(1), stream(2), stream(3),
                                            stream(4), stream(5), stream(6), stream(7)};
      tracer.trace_coherent(x, y, rngs.data(), in_batch, batch.data(), rays);
      next = 0;
    }
    const PixelSample& one = batch[next++];
    ++taken;
    sum.radiance += one.radiance;
    sum.normal += one.normal;
    sum.albedo += one.albedo;
    for (int c = 0; c < layout.coverage_count; ++c) sum.coverage[c] += one.coverage[c];
    sum.sky += one.sky;
    if (one.hit) {
      ++sums.hits;
      sums.depth += one.depth;
      sums.position += one.position.cast<double>();
    }
    layout.mattes->add(sums.mattes, one.object, one.coverage);
    if (layout.adaptive) {
      noise.add(luminance(one.radiance));
      // Decide every 8 samples: the estimate needs a few to settle, and the
      // decision only ever looks at this pixel's own samples, so the image
      // stays the same for any thread count or tiling.
      if (taken >= settings.min_samples && taken % 8 == 0 &&
          noise.relative_error() < settings.noise_target)
        break;
    }
  }
  return sums;
}

// Z where no sample met anything: far, as Blender writes its background.
constexpr float kFarZ = 1e10f;

// Writes the mean of `taken` samples into row `row` of the image, in the
// order of image_channels(). Z and P are means over the samples that hit
// (an edge pixel's P lies on the ground, not between it and the sky).
void store_pixel(Image& image, int x, int row, const PixelSums& sums, int taken,
                 const FrameLayout& layout) {
  const PixelSample& sum = sums.sum;
  const float inv = 1.0f / static_cast<float>(taken);
  int c = 0;
  auto put = [&](float v) { image.at(x, row, c++) = v; };
  for (int i = 0; i < 3; ++i) put(sum.radiance[i] * inv);
  put(sums.hits ? static_cast<float>(sums.depth / sums.hits) : kFarZ);
  for (int i = 0; i < 3; ++i) put(sum.normal[i] * inv);
  for (int i = 0; i < 3; ++i) put(sum.albedo[i] * inv);
  // P in double until it is relative to the header's origin: float32 then
  // keeps a millimetre within 10 km of it.
  const Eigen::Vector3d p = sums.hits
                                ? Eigen::Vector3d(sums.position / sums.hits + layout.local_to_world)
                                : Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) put(static_cast<float>(p[i]));
  for (int i = 0; i < layout.coverage_count; ++i) put(sum.coverage[i] * inv);
  put(sum.sky * inv);
  if (layout.adaptive) put(static_cast<float>(taken));
  layout.mattes->write(sums.mattes, taken, &image.at(x, row, c));
}

// The header: OpenEXR's camera matrices, the CRS and P's origin, the
// mattes' metadata.
void describe_frame(Image& image, const SceneInput& input, const CameraRays& camera,
                    const FrameLayout& layout, const Eigen::Vector3d& world_origin) {
  image.header_matrices = {{"worldToCamera", world_to_camera(camera, layout.local_to_world)},
                           {"worldToNDC", world_to_ndc(camera, layout.local_to_world)}};
  image.header_vectors = {
      {"worldOrigin",
       {static_cast<float>(world_origin.x()), static_cast<float>(world_origin.y()),
        static_cast<float>(world_origin.z())}}};
  if (!input.terrain.geo().crs_wkt.empty())
    image.header_texts.emplace_back("crsWKT", input.terrain.geo().crs_wkt);
  for (const CryptomatteLayer* layer : {&layout.mattes->material(), &layout.mattes->object()})
    for (auto& entry : layer->header()) image.header_texts.push_back(std::move(entry));
}

}  // namespace

Image render_image(const TerrainScene& scene, const SceneInput& input, const Camera& camera,
                   const RenderSettings& settings, const ProgressFn& progress, RenderStats* stats) {
  const int row_begin = settings.row_begin;
  const int row_end = settings.row_end > 0 ? settings.row_end : settings.height;
  check_settings(settings, row_begin, row_end);
  const int col_begin = settings.col_begin;
  const int col_end = settings.col_end > 0 ? settings.col_end : settings.width;
  if (col_begin < 0 || col_begin >= col_end || col_end > settings.width)
    throw Error("columns [" + std::to_string(col_begin) + ", " + std::to_string(col_end) +
                ") are not inside the " + std::to_string(settings.width) + "-column frame");
  const int band = row_end - row_begin, span = col_end - col_begin;
  const FrameMattes mattes(scene, input);
  // P's origin: the scene's own (the DEM's centre) in whole metres, exact as
  // the header's float32 vector (integers below 2^24: any UTM coordinate).
  const Eigen::Vector3d world_origin = scene.origin().array().round().matrix();
  FrameLayout layout;
  layout.coverage_count = static_cast<int>(scene.coverage_names().size());
  layout.adaptive = settings.noise_target > 0.0f;
  layout.mattes = &mattes;
  layout.local_to_world = scene.origin() - world_origin;
  const std::vector<std::string> channels = image_channels(scene, layout);
  // The image, and its file encoded in memory before it is written: half as
  // much again, measured at 3000 x 2000 (28 channels: 940 MiB over the
  // program's own for EXR, 899 for PNG; MemoryEstimate.ImagesOfRenderCompareAndSheet).
  require_memory(static_cast<std::uint64_t>(span) * band * channels.size() * sizeof(float) * 3 / 2,
                 "a " + std::to_string(span) + " x " + std::to_string(band) + " image of " +
                     std::to_string(channels.size()) + " channels",
                 "render a smaller --size, or the frame in --tile bands joined by drift merge");
  Image image(span, band, channels);
  if (band != settings.height || span != settings.width)
    image.frame = {col_begin, row_begin, settings.width, settings.height};

  const CameraRays camera_rays = make_camera_rays(scene, camera, settings.width, settings.height);
  const PathTracer tracer(scene, input, camera_rays, settings);
  describe_frame(image, input, camera_rays, layout, world_origin);

  // Tiles of kTile x kTile pixels, in parallel; every pixel's samples are its
  // own, so the order does not matter.
  constexpr int kTile = 32;
  const int tiles_x = (span + kTile - 1) / kTile;
  const int tiles_y = (band + kTile - 1) / kTile;
  const int tile_count = tiles_x * tiles_y;
  std::atomic<int> done{0};
  std::atomic<bool> cancelled{false};
  std::atomic<std::uint64_t> total_rays{0}, total_samples{0};
  progress(0.0, "rendering");
  tbb::parallel_for(0, tile_count, [&](int tile) {
    if (cancelled.load(std::memory_order_relaxed)) return;
    const int x0 = col_begin + (tile % tiles_x) * kTile, y0 = row_begin + (tile / tiles_x) * kTile;
    std::uint64_t tile_rays = 0, tile_samples = 0;
    for (int y = y0; y < std::min(y0 + kTile, row_end); ++y) {
      for (int x = x0; x < std::min(x0 + kTile, col_end); ++x) {
        int taken = 0;
        const PixelSums sums = sample_pixel(tracer, settings, x, y, layout, taken, tile_rays);
        tile_samples += static_cast<std::uint64_t>(taken);
        store_pixel(image, x - col_begin, y - row_begin, sums, taken, layout);
      }
    }
    total_rays += tile_rays;
    total_samples += tile_samples;  // integer sums: the same whatever the order
    const int finished = ++done;
    if (!progress(static_cast<double>(finished) / tile_count, "")) cancelled = true;
  });
  if (cancelled) throw Cancelled();
  if (stats) {
    stats->camera_rays = total_samples;
    stats->rays = total_rays;
  }
  return image;
}

}  // namespace drift::render
