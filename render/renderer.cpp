#include "render/renderer.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "render/color.h"
#include "render/path_tracer.h"
#include "render/random.h"
#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::render {

namespace {

using Eigen::Vector3f;
constexpr float kPi = std::numbers::pi_v<float>;

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

Vector3f sky_radiance(const Sky& sky, const Vector3f& dir) {
  if (sky.constant) return Vector3f::Constant(sky.intensity);
  if (dir.z() < 0.0f) return sky.horizon * (sky.intensity * sky.ground_factor);
  // A smooth rise from the pale horizon to the deep zenith, flat at the horizon
  // so there is no visible seam with the below-horizon haze.
  const float e = std::clamp(dir.z() / 0.7f, 0.0f, 1.0f);
  const float t = 0.5f - 0.5f * std::cos(kPi * e);
  return (sky.horizon * (1.0f - t) + sky.zenith * t) * sky.intensity;
}

Camera default_camera(const TerrainScene& scene) {
  // Stand on the far side of the DEM's centre from its highest point, above the
  // terrain, and look at the summit across the whole DEM. A summit at the very
  // centre is looked at from the south.
  const Vector3f top = scene.highest_point();
  Eigen::Vector2f away = -top.head<2>();
  if (away.norm() < 1e-3f * scene.extent().norm()) away = {0.0f, -1.0f};
  away.normalize();
  const float half = 0.5f * scene.extent().minCoeff();
  const Eigen::Vector2f xy = away * (0.9f * half);
  // Slightly above the summit, so ridges between camera and peak do not hide it.
  const float z = std::max(scene.height_at(xy.x(), xy.y()), top.z()) + 0.12f * half;
  const Eigen::Vector3d origin = scene.origin();
  Camera camera;
  camera.from = origin + Eigen::Vector3d(xy.x(), xy.y(), z);
  // Aim a little below the summit: the peak sits in the upper part of the frame
  // and the slopes in front fill the rest.
  camera.to = origin + top.cast<double>() - Eigen::Vector3d(0, 0, 0.25 * half);
  camera.vertical_fov_deg = 45.0;
  return camera;
}

CameraRays make_camera_rays(const TerrainScene& scene, const Camera& camera, int width,
                            int height) {
  CameraRays p;
  p.eye = scene.to_local(camera.from);
  p.forward = scene.to_local(camera.to) - p.eye;
  if (!(p.forward.norm() > 0.0f)) throw Error("camera 'from' and 'to' are the same point");
  p.forward.normalize();
  p.right = p.forward.cross(Vector3f::UnitZ());
  if (p.right.norm() < 1e-6f) p.right = p.forward.cross(Vector3f::UnitY());
  p.right.normalize();
  p.up = p.right.cross(p.forward);
  p.aspect = static_cast<float>(width) / static_cast<float>(height);
  if (camera.focal_length_mm) {
    // Horizontal half-width of the sensor over the focal length.
    p.tan_half =
        static_cast<float>(camera.sensor_width_mm / (2.0 * *camera.focal_length_mm)) / p.aspect;
    if (camera.f_number > 0.0) {
      p.lens_radius = static_cast<float>(*camera.focal_length_mm / 1000.0 / camera.f_number / 2.0);
      p.focus_distance =
          static_cast<float>(camera.focus_distance.value_or((camera.to - camera.from).norm()));
    }
  } else {
    p.tan_half = static_cast<float>(std::tan(camera.vertical_fov_deg * std::numbers::pi / 360.0));
  }
  p.width = width;
  p.height = height;
  return p;
}

Vector3f CameraRays::direction(float x, float y) const {
  const float sx = (2.0f * x / static_cast<float>(width) - 1.0f) * tan_half * aspect;
  const float sy = (1.0f - 2.0f * y / static_cast<float>(height)) * tan_half;
  return (forward + right * sx + up * sy).normalized();
}

void CameraRays::ray(float x, float y, float u1, float u2, Vector3f& origin, Vector3f& dir) const {
  dir = direction(x, y);
  origin = eye;
  if (lens_radius <= 0.0f) return;
  // Uniform point on the lens disc; the ray aims at where the pinhole ray
  // crosses the focal plane (distance focus_distance along `forward`).
  const float r = lens_radius * std::sqrt(u1), phi = 2.0f * kPi * u2;
  const Vector3f focus = eye + dir * (focus_distance / dir.dot(forward));
  origin = eye + right * (r * std::cos(phi)) + up * (r * std::sin(phi));
  dir = (focus - origin).normalized();
}

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

// The image's channels, in the order store_pixel writes them.
std::vector<std::string> image_channels(const TerrainScene& scene, bool adaptive) {
  std::vector<std::string> channels = {"R",        "G",        "B",        "depth",    "normal.X",
                                       "normal.Y", "normal.Z", "albedo.R", "albedo.G", "albedo.B"};
  for (const std::string& name : scene.coverage_names()) channels.push_back("coverage." + name);
  channels.emplace_back("mask.sky");
  if (adaptive) channels.emplace_back("samples");
  return channels;
}

// The samples of one pixel: samples_per_pixel, or fewer once the noise target
// is met. Returns their sum and sets `taken`.
PixelSample sample_pixel(const PathTracer& tracer, const RenderSettings& settings, int x, int y,
                         int coverage_count, int& taken, std::uint64_t& rays) {
  PixelSample sum;
  PixelNoise noise;
  const std::uint64_t pixel = static_cast<std::uint64_t>(y) * settings.width + x;
  const bool adaptive = settings.noise_target > 0.0f;
  taken = 0;
  while (taken < settings.samples_per_pixel) {
    SampleStream rng(settings.seed, pixel, static_cast<std::uint64_t>(taken));
    const PixelSample one = tracer.trace(x, y, rng, rays);
    ++taken;
    sum.radiance += one.radiance;
    sum.depth += one.depth;
    sum.normal += one.normal;
    sum.albedo += one.albedo;
    for (int c = 0; c < coverage_count; ++c) sum.coverage[c] += one.coverage[c];
    sum.sky += one.sky;
    if (adaptive) {
      noise.add(luminance(one.radiance));
      // Decide every 8 samples: the estimate needs a few to settle, and the
      // decision only ever looks at this pixel's own samples, so the image
      // stays the same for any thread count or tiling.
      if (taken >= settings.min_samples && taken % 8 == 0 &&
          noise.relative_error() < settings.noise_target)
        break;
    }
  }
  return sum;
}

// Writes the mean of `taken` samples into row `row` of the image, in the
// order of image_channels().
void store_pixel(Image& image, int x, int row, const PixelSample& sum, int taken,
                 int coverage_count, bool adaptive) {
  const float inv = 1.0f / static_cast<float>(taken);
  int c = 0;
  auto put = [&](float v) { image.at(x, row, c++) = v; };
  for (int i = 0; i < 3; ++i) put(sum.radiance[i] * inv);
  put(sum.depth * inv);
  for (int i = 0; i < 3; ++i) put(sum.normal[i] * inv);
  for (int i = 0; i < 3; ++i) put(sum.albedo[i] * inv);
  for (int i = 0; i < coverage_count; ++i) put(sum.coverage[i] * inv);
  put(sum.sky * inv);
  if (adaptive) put(static_cast<float>(taken));
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
  const bool adaptive = settings.noise_target > 0.0f;
  const int coverage_count = static_cast<int>(scene.coverage_names().size());
  const std::vector<std::string> channels = image_channels(scene, adaptive);
  // The image and the film's per-pixel sums (about as much again).
  require_memory(
      static_cast<std::uint64_t>(span) * band * channels.size() * sizeof(float) * 2,
      "a " + std::to_string(span) + " x " + std::to_string(band) + " image of " +
          std::to_string(channels.size()) + " channels",
      "render a smaller --size, or the frame in --tile bands joined by drift merge");
  Image image(span, band, channels);
  if (band != settings.height || span != settings.width)
    image.frame = {col_begin, row_begin, settings.width, settings.height};

  const CameraRays camera_rays = make_camera_rays(scene, camera, settings.width, settings.height);
  const PathTracer tracer(scene, input, camera_rays, settings);

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
        const PixelSample sum =
            sample_pixel(tracer, settings, x, y, coverage_count, taken, tile_rays);
        tile_samples += static_cast<std::uint64_t>(taken);
        store_pixel(image, x - col_begin, y - row_begin, sum, taken, coverage_count, adaptive);
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
