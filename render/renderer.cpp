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

#include "render/bsdf.h"
#include "render/color.h"
#include "render/light_shafts.h"
#include "render/physical_sky.h"
#include "render/random.h"
#include "render/sampling.h"
#include "render/sky_sampler.h"
#include "terrain/direction.h"
#include "terrain/error.h"

namespace drift::render {

namespace {

using Eigen::Vector3f;
constexpr float kPi = std::numbers::pi_v<float>;

float ray_epsilon(const Vector3f& p) { return 1e-4f * (1.0f + p.cwiseAbs().maxCoeff()); }

struct PixelSample {
  Vector3f radiance{0, 0, 0};
  float depth = 0.0f;
  Vector3f normal{0, 0, 0};
  Vector3f albedo{0, 0, 0};
  Coverage coverage{};  // by TerrainScene::coverage_names()
  float sky = 0.0f;     // 1 where the camera sees the sky
};

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

Image render_image(const TerrainScene& scene, const SceneInput& input, const Camera& camera,
                   const RenderSettings& settings, const ProgressFn& progress, RenderStats* stats) {
  if (settings.width < 1 || settings.height < 1 || settings.samples_per_pixel < 1 ||
      settings.max_depth < 1 || settings.min_samples < 1) {
    throw Error(
        "render size, samples per pixel, minimum samples and max depth must all be at least 1");
  }
  if (!(settings.noise_target >= 0.0f)) throw Error("the noise target must be 0 (off) or more");
  const int row_begin = settings.row_begin;
  const int row_end = settings.row_end > 0 ? settings.row_end : settings.height;
  if (row_begin < 0 || row_begin >= row_end || row_end > settings.height) {
    throw Error("rows [" + std::to_string(row_begin) + ", " + std::to_string(row_end) +
                ") are not inside the " + std::to_string(settings.height) + "-row frame");
  }
  const int band = row_end - row_begin;
  std::vector<std::string> channels = {"R",        "G",        "B",        "depth",    "normal.X",
                                       "normal.Y", "normal.Z", "albedo.R", "albedo.G", "albedo.B"};
  const int coverage_count = static_cast<int>(scene.coverage_names().size());
  for (const std::string& name : scene.coverage_names()) channels.push_back("coverage." + name);
  channels.emplace_back("mask.sky");
  if (settings.noise_target > 0.0f) channels.emplace_back("samples");
  Image image(settings.width, band, channels);

  if (band != settings.height) image.frame = {0, row_begin, settings.width, settings.height};

  const CameraRays camera_rays = make_camera_rays(scene, camera, settings.width, settings.height);

  const Sun& sun = input.sun;
  const Vector3f sun_dir =
      terrain::direction_from_az_el(sun.azimuth_deg, sun.elevation_deg).cast<float>();
  const float sun_cos_max =
      static_cast<float>(std::cos(sun.angular_diameter_deg * std::numbers::pi / 360.0));
  const Vector3f sun_irradiance = sun.color * static_cast<float>(sun.irradiance);
  const bool sun_up = sun.irradiance > 0.0 && sun_dir.z() > -0.2f;

  // The physical atmosphere, precomputed for this camera and sun.
  std::unique_ptr<Atmosphere> atmosphere;
  std::unique_ptr<PhysicalSky> air;
  if (input.sky.model == SkyModel::Physical && !input.sky.constant) {
    AtmosphereParameters parameters;
    parameters.aerosol_scale = input.sky.haze;
    atmosphere = std::make_unique<Atmosphere>(parameters);
    const double camera_altitude = scene.origin().z() + camera_rays.eye.z();
    const double reach = camera_rays.eye.head<2>().norm() + scene.extent().norm() + scene.surround_reach();
    air = std::make_unique<PhysicalSky>(*atmosphere, camera_altitude, sun_dir.cast<double>(),
                                        static_cast<float>(sun.irradiance), reach);
  }
  const float base_altitude = static_cast<float>(scene.origin().z());
  auto sky_light = [&](const Vector3f& d) {
    return air ? air->sky(d) : sky_radiance(input.sky, d);
  };
  // Light shafts: what the terrain's shadow takes from a camera ray's air.
  const bool shafts = air && input.sky.light_shafts && sun_up;
  const ShadowSlab shadow_slab{scene.bottom(), scene.top()};
  const auto in_shadow = [&](const Vector3f& p) { return scene.occluded(p, sun_dir, 1e30f); };
  const float air_reach = camera_rays.eye.head<2>().norm() + scene.extent().norm() + scene.surround_reach();
  auto shaft_loss = [&](const Vector3f& origin, const Vector3f& dir, float distance, float jitter,
                        std::uint64_t& rays) {
    rays += static_cast<std::uint64_t>(input.sky.shaft_steps);
    return shaft_shadow_loss(*air, base_altitude, {origin, dir, distance}, shadow_slab,
                             input.sky.shaft_steps, jitter, in_shadow);
  };
  // The sky as a light, tabulated once for this camera and sun and
  // importance-sampled at every vertex (render/sky_sampler.h).
  std::optional<SkySampler> sky_sampler;
  if (settings.sample_sky) sky_sampler.emplace(sky_light);

  auto trace = [&](int px, int py, SampleStream& rng, std::uint64_t& rays) {
    PixelSample out;
    const float jx = rng.next(), jy = rng.next();
    Vector3f origin, dir;
    // Lens samples only for a thin lens, so pinhole renders keep their bits.
    const float lu = camera_rays.lens_radius > 0.0f ? rng.next() : 0.0f;
    const float lv = camera_rays.lens_radius > 0.0f ? rng.next() : 0.0f;
    camera_rays.ray(static_cast<float>(px) + jx, static_cast<float>(py) + jy, lu, lv, origin, dir);
    const float shaft_jitter = shafts ? rng.next() : 0.0f;  // likewise only when used
    Vector3f throughput(1, 1, 1);
    // Camera rays start as wide as a pixel's angle; see RayCone.
    RayCone cone{0.0f, 2.0f * camera_rays.tan_half / static_cast<float>(settings.height)};
    float bounce_pdf = 0.0f;  // density of the BSDF sample that led here
    // Vertices 0 .. max_depth - 1 are shaded; the ray leaving the last one is
    // traced too, only to see whether it escapes to the sky, so that both
    // strategies of the last vertex's sky light are there (PBRT's loop).
    for (int depth = 0;; ++depth) {
      Hit hit;
      ++rays;
      if (!scene.intersect(origin, dir, hit, cone)) {
        if (depth == 0) out.sky = 1.0f;
        // An escaping bounce is the BSDF strategy's sample of the sky,
        // weighted against the sky's own (camera rays see it as it is, less
        // the terrain's shadow on the air with light shafts).
        Vector3f light = sky_light(dir);
        if (depth == 0 && shafts) {
          light -= shaft_loss(origin, dir, air_reach, shaft_jitter, rays);
          light = light.cwiseMax(0.0f);
        }
        const float w =
            depth > 0 && sky_sampler ? power_heuristic(bounce_pdf, sky_sampler->pdf(dir)) : 1.0f;
        out.radiance += throughput.cwiseProduct(light) * w;
        break;
      }
      if (air) {
        // The air between the ray's start and the hit: in-scattered light
        // added, the light from behind attenuated (aerial perspective).
        const AirSegment seg =
            depth == 0 ? air->from_camera(dir, hit.distance)
                       : air->segment(base_altitude + 0.5f * (origin.z() + hit.position.z()), dir,
                                      hit.distance);
        Vector3f inscatter = seg.inscatter;
        if (depth == 0 && shafts) {
          inscatter -= shaft_loss(origin, dir, hit.distance, shaft_jitter, rays);
          inscatter = inscatter.cwiseMax(0.0f);
        }
        out.radiance += throughput.cwiseProduct(inscatter);
        throughput = throughput.cwiseProduct(seg.transmittance);
      }
      if (depth == settings.max_depth) break;
      if (depth == 0) {
        out.depth = hit.distance;
        out.normal = hit.normal;
        out.albedo = hit.material.albedo;
        out.coverage = hit.coverage;
      }
      const Vector3f wo = -dir;
      const Vector3f p = hit.position + hit.normal * ray_epsilon(hit.position);
      const GroundBsdf bsdf(hit.normal, wo, hit.material);
      // Next-event estimation of the sun: uniform in its cone, pdf 1/solid angle,
      // radiance E/solid angle, so the estimate is E * cos * f.
      const float u1 = rng.next(), u2 = rng.next();
      if (sun_up) {
        const Vector3f l = cone_sample(sun_dir, sun_cos_max, u1, u2);
        const float cos_l = hit.normal.dot(l);
        if (cos_l > 0.0f && l.z() > -0.2f && (++rays, !scene.occluded(p, l, 1e30f))) {
          const Vector3f e =
              air ? air->sun_irradiance(base_altitude + hit.position.z()) : sun_irradiance;
          out.radiance += throughput.cwiseProduct(bsdf.eval(l)).cwiseProduct(e) * cos_l;
        }
      }
      // Next-event estimation of the sky, weighted against the BSDF's sample
      // of the same direction by the power heuristic (Veach 1997, eq. 9.13).
      const float s1 = rng.next(), s2 = rng.next();
      SkySampler::Sample light;
      if (sky_sampler && sky_sampler->sample(s1, s2, light)) {
        const float cos_l = hit.normal.dot(light.dir);
        const Vector3f f = cos_l > 0.0f ? bsdf.eval(light.dir) : Vector3f::Zero();
        if (f.maxCoeff() > 0.0f && (++rays, !scene.occluded(p, light.dir, 1e30f))) {
          const float w = power_heuristic(light.pdf, bsdf.pdf(light.dir));
          out.radiance += throughput.cwiseProduct(f).cwiseProduct(sky_light(light.dir)) *
                          (cos_l * w / light.pdf);
        }
      }
      // Bounce by the BSDF: cosine-weighted on dry ground (weight: the albedo
      // times the Oren-Nayar factor), the wet coat's lobe by its probability.
      // Dry ground draws no lobe number.
      const float u_lobe = bsdf.specular_probability() > 0.0f ? rng.next() : 0.0f;
      const float b1 = rng.next(), b2 = rng.next();
      GroundBsdf::Sample bounce;
      if (!bsdf.sample(u_lobe, b1, b2, bounce)) break;
      bounce_pdf = bounce.pdf;
      dir = bounce.wi;
      origin = p;
      throughput = throughput.cwiseProduct(bounce.weight);
      // A diffuse bounce spreads the footprint over about a radian.
      cone = {cone.width + cone.spread * hit.distance, 1.0f};
      if (depth >= 2) {  // Russian roulette (unbiased)
        const float q = std::min(0.95f, throughput.maxCoeff());
        if (rng.next() >= q) break;
        throughput /= q;
      }
    }
    return out;
  };

  constexpr int kTile = 32;
  const int tiles_x = (settings.width + kTile - 1) / kTile;
  const int tiles_y = (band + kTile - 1) / kTile;
  const int tile_count = tiles_x * tiles_y;
  std::atomic<int> done{0};
  std::atomic<bool> cancelled{false};
  std::atomic<std::uint64_t> total_rays{0}, total_samples{0};
  progress(0.0, "rendering");
  const bool adaptive = settings.noise_target > 0.0f;
  tbb::parallel_for(0, tile_count, [&](int tile) {
    if (cancelled.load(std::memory_order_relaxed)) return;
    const int x0 = (tile % tiles_x) * kTile, y0 = row_begin + (tile / tiles_x) * kTile;
    std::uint64_t tile_rays = 0, tile_samples = 0;
    for (int y = y0; y < std::min(y0 + kTile, row_end); ++y) {
      for (int x = x0; x < std::min(x0 + kTile, settings.width); ++x) {
        PixelSample sum;
        PixelNoise noise;
        const std::uint64_t pixel = static_cast<std::uint64_t>(y) * settings.width + x;
        int taken = 0;
        while (taken < settings.samples_per_pixel) {
          SampleStream rng(settings.seed, pixel, static_cast<std::uint64_t>(taken));
          const PixelSample one = trace(x, y, rng, tile_rays);
          ++taken;
          sum.radiance += one.radiance;
          sum.depth += one.depth;
          sum.normal += one.normal;
          sum.albedo += one.albedo;
          for (int c = 0; c < coverage_count; ++c) sum.coverage[c] += one.coverage[c];
          sum.sky += one.sky;
          if (adaptive) {
            noise.add(luminance(one.radiance));
            // Decide every 8 samples: the estimate needs a few to settle, and
            // the decision only ever looks at this pixel's own samples, so
            // the image stays the same for any thread count or tiling.
            if (taken >= settings.min_samples && taken % 8 == 0 &&
                noise.relative_error() < settings.noise_target)
              break;
          }
        }
        tile_samples += static_cast<std::uint64_t>(taken);
        const float inv = 1.0f / static_cast<float>(taken);
        // In the order of `channels`.
        int c = 0;
        auto put = [&](float v) { image.at(x, y - row_begin, c++) = v; };
        for (int i = 0; i < 3; ++i) put(sum.radiance[i] * inv);
        put(sum.depth * inv);
        for (int i = 0; i < 3; ++i) put(sum.normal[i] * inv);
        for (int i = 0; i < 3; ++i) put(sum.albedo[i] * inv);
        for (int i = 0; i < coverage_count; ++i) put(sum.coverage[i] * inv);
        put(sum.sky * inv);
        if (adaptive) put(static_cast<float>(taken));
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
