#include "render/path_tracer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>

#include "render/sampling.h"
#include "terrain/angles.h"
#include "terrain/direction.h"
#include "terrain/error.h"

namespace drift::render {

namespace {

using Eigen::Vector3f;
constexpr float kPi = std::numbers::pi_v<float>;

float ray_epsilon(const Vector3f& p) { return 1e-4f * (1.0f + p.cwiseAbs().maxCoeff()); }

// Clouds lighting a vertex (its sky samples and the escapes of its bounces,
// both one function for MIS) are seen through a footprint widening by this
// per metre: light averages over them, so the finest octaves are not needed.
constexpr float kCloudLightingSpread = 0.05f;

// Path vertices (from the camera's hit on) that take a sample of the sky as a
// light, weighted by MIS against their bounce's escape. Deeper vertices see
// the sky through their bounce alone: after one diffuse bounce the path
// carries a tenth or less of the light (albedo ~0.1-0.3), the clear sky is
// smooth enough for cosine sampling, and the sky's shadow rays were the
// costliest rays of the frame (grazing rays across the DEM and its
// surround, ~20 % of the CPU time of the default frame against ~7 % for the
// sun's). docs/rendering.md ("Speed") gives the time and relMSE it costs.
constexpr int kSkySampledVertices = 1;

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

PathTracer::PathTracer(const TerrainScene& scene, const SceneInput& input, const CameraRays& camera,
                       const RenderSettings& settings)
    : scene_(scene),
      input_(input),
      camera_(camera),
      settings_(settings),
      objects_(input.meshes, scene.origin()) {
  const Sun& sun = input.sun;
  sun_dir_ = terrain::direction_from_az_el(sun.azimuth_deg, sun.elevation_deg).cast<float>();
  sun_cos_max_ = static_cast<float>(std::cos(terrain::radians(0.5 * sun.angular_diameter_deg)));
  sun_irradiance_ = sun.color * static_cast<float>(sun.irradiance);
  sun_up_ = sun.irradiance > 0.0 && sun_dir_.z() > -0.2f;

  // The physical atmosphere, precomputed for this camera and sun.
  if (input.sky.model == SkyModel::Physical && !input.sky.constant) {
    AtmosphereParameters parameters;
    parameters.aerosol_scale = input.sky.haze;
    atmosphere_ = std::make_unique<Atmosphere>(parameters);
    const double camera_altitude = scene.origin().z() + camera.eye.z();
    double reach = camera.eye.head<2>().norm() + scene.extent().norm() +
                   scene.surround_reach();  // the ground beyond the DEM (render/surround.h)
    if (input.clouds.enabled) {             // the aerial perspective reaches the clouds too
      clouds_.emplace(input.clouds, scene.origin());
      reach = std::max(reach, std::min(clouds_->horizon_distance(camera.eye.z()), 3e5));
    }
    air_ = std::make_unique<PhysicalSky>(*atmosphere_, camera_altitude, sun_dir_.cast<double>(),
                                         static_cast<float>(sun.irradiance), reach);
  }
  base_altitude_ = static_cast<float>(scene.origin().z());
  if (input.clouds.enabled) init_clouds(input);
  // Light shafts: what the terrain's shadow takes from a camera ray's air.
  shafts_ = air_ && input.sky.light_shafts && sun_up_;
  shadow_slab_ = {scene.bottom(), scene.top()};
  air_reach_ = camera.eye.head<2>().norm() + scene.extent().norm() + scene.surround_reach();
  // The sky as a light, tabulated once for this camera and sun and
  // importance-sampled at every vertex (render/sky_sampler.h); above the
  // horizon only. Below it the air is bright too (57-68 % of the whole
  // sphere's luminance in the snowfall and default scenes), but from the
  // ground those directions meet the ground or the surface itself, so such
  // samples were wasted; the BSDF's bounces alone cover them (MIS weight 1
  // where the sampler's density is 0), and the sky's samples all land where
  // a shaded slope can see them.
  if (settings.sample_sky) {
    sky_sampler_.emplace([this](const Vector3f& d) -> Vector3f {
      return d.z() > 0.0f ? sky_light(d) : Vector3f::Zero();
    });
  }
}

PathTracer::~PathTracer() = default;

void PathTracer::init_clouds(const SceneInput& input) {
  if (!air_) {
    throw Error(
        "clouds need the physical sky: set [sky] model = \"physical\" (and constant = false) or "
        "remove [clouds]");
  }
  // The layer's light: the sun at its altitude, through the same atmosphere,
  // and the diffuse light of the sky above and of the ground below (a mean
  // mountain albedo of 0.15).
  const float altitude = static_cast<float>(input.clouds.altitude);
  cloud_light_.sun = sun_up_ ? air_->sun_irradiance(altitude) : Vector3f::Zero();
  cloud_light_.sun_dir = sun_dir_;
  sun_penumbra_ = static_cast<float>(terrain::radians(input.sun.angular_diameter_deg));
  const Vector3f level = air_->level_irradiance();
  const float camera_altitude = base_altitude_ + camera_.eye.z();
  cloud_light_.sky_down =
      (level - air_->sun_irradiance(camera_altitude) * std::max(sun_dir_.z(), 0.0f)).cwiseMax(0.0f);
  cloud_light_.ground_up = 0.15f * level;
  // The air beneath the layer gets the sun through it: on average its mean
  // transmittance towards the sun (render/clouds.h).
  air_under_clouds_ = sun_up_ ? clouds_->mean_sun_transmittance(sun_dir_) : 1.0f;
  cloud_altitude_ = altitude - base_altitude_;
}

CloudLight PathTracer::light_on_clouds(const CloudCrossing& c, std::uint64_t& rays) const {
  // A layer lower than the peaks lies in their shadow where the terrain
  // stands between it and the sun (a layer above every peak never does).
  if (c.point.z() >= shadow_slab_.top || cloud_light_.sun.maxCoeff() <= 0.0f) return cloud_light_;
  ++rays;
  if (!scene_.occluded(c.point, sun_dir_, 1e30f)) return cloud_light_;
  CloudLight shaded = cloud_light_;
  shaded.sun.setZero();
  return shaded;
}

float PathTracer::air_shade(float z0, float z1) const {
  // The layer's mean shadow on air below it (both ends under the layer).
  return clouds_ && std::max(z0, z1) < cloud_altitude_ ? air_under_clouds_ : 1.0f;
}

Vector3f PathTracer::sky_light(const Vector3f& dir) const {
  return air_ ? air_->sky(dir) : sky_radiance(input_.sky, dir);
}

Vector3f PathTracer::shaft_loss(const Path& path, float distance, std::uint64_t& rays) const {
  rays += static_cast<std::uint64_t>(input_.sky.shaft_steps);
  const auto in_shadow = [&](const Vector3f& p) { return scene_.occluded(p, sun_dir_, 1e30f); };
  return shaft_shadow_loss(*air_, base_altitude_, {path.origin, path.dir, distance}, shadow_slab_,
                           input_.sky.shaft_steps, path.shaft_jitter, in_shadow);
}

Vector3f PathTracer::cloudy_sky(const Vector3f& origin, const Vector3f& dir, const Vector3f& behind,
                                bool from_camera, const RayCone& cone, std::uint64_t& rays) const {
  CloudCrossing c;
  if (!clouds_ || !clouds_->cross(origin, dir, 1e30f, c)) return behind;
  const float footprint = cone.width_at(c.distance);
  const CloudLook look = cloud_look(*clouds_, c, dir, light_on_clouds(c, rays), footprint);
  if (look.transmittance >= 1.0f) return behind;
  // The sky's light is the air before the layer, the layer, and what lies
  // beyond: L = T_c L_sky + (1 - T_c) L_air(0, d) + T_air(0, d) L_cloud.
  const AirSegment air =
      from_camera
          ? air_->from_camera(dir, c.distance)
          : air_->segment(base_altitude_ + 0.5f * (origin.z() + c.point.z()), dir, c.distance);
  return look.transmittance * behind +
         (1.0f - look.transmittance) * air_shade(origin.z(), c.point.z()) * air.inscatter +
         air.transmittance.cwiseProduct(look.radiance);
}

void PathTracer::cross_clouds(Path& path, float distance, int depth, PixelSample& out,
                              std::uint64_t& rays) const {
  // Ground seen through the layer: the same composition as cloudy_sky's,
  // with the air and ground behind added by cross_air through the throughput.
  CloudCrossing c;
  if (!clouds_->cross(path.origin, path.dir, distance, c)) return;
  const float footprint = path.cone.width_at(c.distance);
  const CloudLook look = cloud_look(*clouds_, c, path.dir, light_on_clouds(c, rays), footprint);
  if (look.transmittance >= 1.0f) return;
  const AirSegment air =
      depth == 0 ? air_->from_camera(path.dir, c.distance)
                 : air_->segment(base_altitude_ + 0.5f * (path.origin.z() + c.point.z()), path.dir,
                                 c.distance);
  out.radiance += path.throughput.cwiseProduct(
      (1.0f - look.transmittance) * air_shade(path.origin.z(), c.point.z()) * air.inscatter +
      air.transmittance.cwiseProduct(look.radiance));
  path.throughput *= look.transmittance;
}

PathTracer::Path PathTracer::camera_path(int px, int py, SampleStream& rng) const {
  Path path;
  // Pixel and lens from one 4-D set: the pixel's samples are stratified in
  // the film plane (coordinates 0 and 1, a (0,2)-sequence) and on the lens
  // (a pinhole takes the first two coordinates only, the same numbers).
  std::array<float, 4> u{};
  if (camera_.lens_radius > 0.0f) {
    u = rng.next4d();
  } else {
    const auto [jx, jy] = rng.next2d();
    u = {jx, jy, 0.0f, 0.0f};
  }
  camera_.ray(static_cast<float>(px) + u[0], static_cast<float>(py) + u[1], u[2], u[3], path.origin,
              path.dir);
  // Every sample passes the same sets in the same order, each used or
  // skipped (render/random.h).
  if (shafts_) {
    path.shaft_jitter = rng.next1d();
  } else {
    rng.skip();
  }
  // Camera rays start as wide as a pixel's angle; see RayCone.
  path.cone = {camera_.footprint_width(), camera_.footprint_spread()};
  return path;
}

PixelSample PathTracer::trace(int px, int py, SampleStream& rng, std::uint64_t& rays) const {
  PixelSample out;
  Path path = camera_path(px, py, rng);
  Hit hit;
  ++rays;
  const bool found = scene_.intersect(path.origin, path.dir, hit, path.cone);
  follow(path, hit, found, rng, out, rays, 0);
  return out;
}

void PathTracer::trace_coherent(int px, int py, SampleStream* rngs, int n, PixelSample* out,
                                std::uint64_t& rays) const {
  if (n < 1 || n > kCoherentSamples) throw Error("trace_coherent takes 1 to 8 samples");
  // The camera rays of a pixel's samples leave one point in nearly one
  // direction: traced as one packet (TerrainScene::intersect_coherent), then
  // each path goes on alone. Each sample draws from its own stream in the
  // order trace() does, so the result is trace()'s, sample by sample.
  std::array<Path, kCoherentSamples> paths;
  std::array<Vector3f, kCoherentSamples> origins, dirs;
  std::array<RayCone, kCoherentSamples> cones;
  std::array<Hit, kCoherentSamples> hits;
  std::array<bool, kCoherentSamples> found{};
  for (int i = 0; i < n; ++i) {
    paths[i] = camera_path(px, py, rngs[i]);
    origins[i] = paths[i].origin, dirs[i] = paths[i].dir, cones[i] = paths[i].cone;
  }
  rays += static_cast<std::uint64_t>(n);
  scene_.intersect_coherent(n, origins.data(), dirs.data(), cones.data(), hits.data(),
                            found.data());
  // The first vertex of every sample up to its sun's shadow ray; those rays
  // (one direction, nearby points) are traced as one packet too.
  std::array<std::optional<GroundBsdf>, kCoherentSamples> bsdfs;
  std::array<Vector3f, kCoherentSamples> points, sun_dirs, shadow_origins, shadow_dirs;
  std::array<int, kCoherentSamples> shadow{};  // sample i's shadow ray (-1: none)
  int shadows = 0;
  for (int i = 0; i < n; ++i) {
    out[i] = PixelSample{};
    if (!found[i]) {
      escape_to_sky(paths[i], 0, out[i], rays);
      continue;
    }
    if (!arrive(paths[i], hits[i], 0, out[i], rays)) continue;
    points[i] = hits[i].position + hits[i].normal * ray_epsilon(hits[i].position);
    bsdfs[i].emplace(hits[i].normal, -paths[i].dir, hits[i].material);
    shadow[i] = -1;
    if (sun_up_) {
      const auto [u1, u2] = rngs[i].next2d();
      if (sun_ray(hits[i], u1, u2, sun_dirs[i])) {
        shadow_origins[shadows] = points[i], shadow_dirs[shadows] = sun_dirs[i];
        shadow[i] = shadows++;
      }
    } else {
      rngs[i].skip();
    }
  }
  rays += static_cast<std::uint64_t>(shadows);
  std::array<bool, kCoherentSamples> blocked{};
  if (shadows > 0)
    scene_.occluded_coherent(shadows, shadow_origins.data(), shadow_dirs.data(), 1e30f,
                             blocked.data());
  for (int i = 0; i < n; ++i) {
    if (!bsdfs[i]) continue;
    if (shadow[i] >= 0 && !blocked[shadow[i]])
      add_sun(paths[i], hits[i], points[i], *bsdfs[i], sun_dirs[i], out[i]);
    if (!leave(paths[i], hits[i], points[i], *bsdfs[i], 0, rngs[i], out[i], rays)) continue;
    Hit next;
    ++rays;
    const bool met = scene_.intersect(paths[i].origin, paths[i].dir, next, paths[i].cone);
    follow(paths[i], next, met, rngs[i], out[i], rays, 1);
  }
}

void PathTracer::follow(Path& path, Hit& hit, bool found, SampleStream& rng, PixelSample& out,
                        std::uint64_t& rays, int first) const {
  // Vertices 0 .. max_depth - 1 are shaded; the ray leaving the last one is
  // traced too, only to see whether it escapes to the sky, so that both
  // strategies of the last vertex's sky light are there (PBRT's loop).
  for (int depth = first;; ++depth) {
    if (depth > first) {
      hit = Hit{};
      ++rays;
      found = scene_.intersect(path.origin, path.dir, hit, path.cone);
    }
    if (!found) {
      escape_to_sky(path, depth, out, rays);
      break;
    }
    if (!arrive(path, hit, depth, out, rays)) break;
    const Vector3f p = hit.position + hit.normal * ray_epsilon(hit.position);
    const GroundBsdf bsdf(hit.normal, -path.dir, hit.material);
    // Every vertex passes the same sets in the same order, each used or
    // skipped, so that a set stands for the same integral in all of a
    // pixel's samples and keeps its stratification (render/random.h).
    if (sun_up_) {
      const auto [u1, u2] = rng.next2d();
      sample_sun(path, hit, p, bsdf, u1, u2, out, rays);
    } else {
      rng.skip();
    }
    if (!leave(path, hit, p, bsdf, depth, rng, out, rays)) break;
  }
}

bool PathTracer::arrive(Path& path, const Hit& hit, int depth, PixelSample& out,
                        std::uint64_t& rays) const {
  if (clouds_) cross_clouds(path, hit.distance, depth, out, rays);
  if (air_) cross_air(path, hit, depth, out, rays);
  if (depth == settings_.max_depth) return false;
  if (depth == 0) {
    out.hit = true;
    out.depth = camera_.view_depth(hit.position);
    out.position = hit.position;
    out.object = 1 + objects_.object_at(path.origin, path.dir, hit.distance);
    out.normal = hit.normal;
    out.albedo = hit.material.albedo;
    out.coverage = hit.coverage;
  }
  return true;
}

bool PathTracer::leave(Path& path, const Hit& hit, const Vector3f& p, const GroundBsdf& bsdf,
                       int depth, SampleStream& rng, PixelSample& out, std::uint64_t& rays) const {
  // The sky's own samples at the first vertex only.
  if (depth < kSkySampledVertices) {
    const auto [s1, s2] = rng.next2d();
    sample_sky(path, hit, p, bsdf, s1, s2, out, rays);
  } else {
    rng.skip();
  }
  return bounce(path, hit, p, bsdf, depth, rng);
}

void PathTracer::escape_to_sky(const Path& path, int depth, PixelSample& out,
                               std::uint64_t& rays) const {
  if (depth == 0) out.sky = 1.0f;
  // An escaping bounce is the BSDF strategy's sample of the sky, weighted
  // against the sky's own (camera rays see it as it is, less the terrain's
  // shadow on the air with light shafts).
  Vector3f light = sky_light(path.dir);
  if (depth == 0 && shafts_) {
    light -= shaft_loss(path, air_reach_, rays);
    light = light.cwiseMax(0.0f);
  }
  if (clouds_) {
    const RayCone cone{path.cone.width, depth == 0 ? path.cone.spread : kCloudLightingSpread};
    light = cloudy_sky(path.origin, path.dir, light, depth == 0, cone, rays);
  }
  // MIS only where the vertex it left sampled the sky too (depth - 1 <
  // kSkySampledVertices); deeper escapes are the sky's one estimate.
  const float w = depth > 0 && depth <= kSkySampledVertices && sky_sampler_
                      ? power_heuristic(path.bounce_pdf, sky_sampler_->pdf(path.dir))
                      : 1.0f;
  out.radiance += path.throughput.cwiseProduct(light) * w;
}

void PathTracer::cross_air(Path& path, const Hit& hit, int depth, PixelSample& out,
                           std::uint64_t& rays) const {
  // The air between the ray's start and the hit: in-scattered light added,
  // the light from behind attenuated (aerial perspective).
  const AirSegment seg =
      depth == 0 ? air_->from_camera(path.dir, hit.distance)
                 : air_->segment(base_altitude_ + 0.5f * (path.origin.z() + hit.position.z()),
                                 path.dir, hit.distance);
  Vector3f inscatter = seg.inscatter * air_shade(path.origin.z(), hit.position.z());
  if (depth == 0 && shafts_) {
    inscatter -= shaft_loss(path, hit.distance, rays);
    inscatter = inscatter.cwiseMax(0.0f);
  }
  out.radiance += path.throughput.cwiseProduct(inscatter);
  path.throughput = path.throughput.cwiseProduct(seg.transmittance);
}

void PathTracer::sample_sun(const Path& path, const Hit& hit, const Vector3f& p,
                            const GroundBsdf& bsdf, float u1, float u2, PixelSample& out,
                            std::uint64_t& rays) const {
  Vector3f l;
  if (sun_ray(hit, u1, u2, l) && (++rays, !scene_.occluded(p, l, 1e30f)))
    add_sun(path, hit, p, bsdf, l, out);
}

bool PathTracer::sun_ray(const Hit& hit, float u1, float u2, Vector3f& l) const {
  // Uniform in the sun's cone: pdf 1/solid angle, radiance E/solid angle, so
  // the estimate is E * cos * f.
  l = cone_sample(sun_dir_, sun_cos_max_, u1, u2);
  return hit.normal.dot(l) > 0.0f && l.z() > -0.2f;
}

void PathTracer::add_sun(const Path& path, const Hit& hit, const Vector3f& p,
                         const GroundBsdf& bsdf, const Vector3f& l, PixelSample& out) const {
  const float cos_l = hit.normal.dot(l);
  Vector3f e = air_ ? air_->sun_irradiance(base_altitude_ + hit.position.z()) : sun_irradiance_;
  // Cloud shadow, blurred as the sun's disc blurs it (its penumbra).
  if (clouds_) {
    const float width = path.cone.width_at(hit.distance);
    e *= clouds_->transmittance(p, l, width, sun_penumbra_);
  }
  out.radiance += path.throughput.cwiseProduct(bsdf.eval(l)).cwiseProduct(e) * cos_l;
}

void PathTracer::sample_sky(const Path& path, const Hit& hit, const Vector3f& p,
                            const GroundBsdf& bsdf, float u1, float u2, PixelSample& out,
                            std::uint64_t& rays) const {
  // Weighted against the BSDF's sample of the same direction by the power
  // heuristic (Veach 1997, eq. 9.13).
  SkySampler::Sample light;
  if (!sky_sampler_ || !sky_sampler_->sample(u1, u2, light)) return;
  const float cos_l = hit.normal.dot(light.dir);
  const Vector3f f = cos_l > 0.0f ? bsdf.eval(light.dir) : Vector3f::Zero();
  if (f.maxCoeff() > 0.0f && (++rays, !scene_.occluded(p, light.dir, 1e30f))) {
    const float w = power_heuristic(light.pdf, bsdf.pdf(light.dir));
    Vector3f sky = sky_light(light.dir);
    if (clouds_) {
      const RayCone cone{path.cone.width_at(hit.distance), kCloudLightingSpread};
      sky = cloudy_sky(p, light.dir, sky, false, cone, rays);
    }
    out.radiance += path.throughput.cwiseProduct(f).cwiseProduct(sky) * (cos_l * w / light.pdf);
  }
}

bool PathTracer::bounce(Path& path, const Hit& hit, const Vector3f& p, const GroundBsdf& bsdf,
                        int depth, SampleStream& rng) const {
  // Cosine-weighted on dry ground (weight: the albedo times the Oren-Nayar
  // factor), the wet coat's lobe by its probability. Sets a sample does not
  // use are skipped, not drawn (the sampler's cost was 4 % of the frame).
  float u_lobe = 0.0f;
  if (bsdf.specular_probability() > 0.0f) {
    u_lobe = rng.next1d();
  } else {
    rng.skip();
  }
  const auto [b1, b2] = rng.next2d();
  float u_roulette = 0.0f;
  if (depth >= 1) {
    u_roulette = rng.next1d();
  } else {
    rng.skip();
  }
  GroundBsdf::Sample sample;
  if (!bsdf.sample(u_lobe, b1, b2, sample)) return false;
  path.bounce_pdf = sample.pdf;
  path.dir = sample.wi;
  path.origin = p;
  path.throughput = path.throughput.cwiseProduct(sample.weight);
  // A diffuse bounce spreads the footprint over about a radian.
  path.cone = {path.cone.width_at(hit.distance), 1.0f};
  // Russian roulette (unbiased) from the second bounce on: a path that has
  // already bounced once off ground of albedo ~0.1-0.3 carries little light,
  // so most of it is cut there and the survivors weighted up. On the default
  // frame this takes 6 % of the rays (2.92 -> 2.76 a sample) and ~10 % of the
  // CPU time for ~2 % more relMSE; from the first bounce it would take 32 %
  // of the rays but nearly double the relMSE (docs/rendering.md, "Speed").
  if (depth >= 1) {
    const float q = std::min(0.95f, path.throughput.maxCoeff());
    if (u_roulette >= q) return false;
    path.throughput /= q;
  }
  return true;
}

}  // namespace drift::render
