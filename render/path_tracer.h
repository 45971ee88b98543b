// The light transport of one camera sample (pbrt's Li): a unidirectional path
// with next-event estimation of the sun and of the importance-sampled sky
// (render/sky_sampler.h), BSDF-sampled bounces (render/bsdf.h) whose escapes to
// the sky are weighed against the sky's samples by multiple importance sampling
// (Veach 1997, eq. 9.13), the air between vertices (aerial perspective and
// light shafts, render/physical_sky.h, render/light_shafts.h) and Russian
// roulette. render_image (render/renderer.h) drives it pixel by pixel.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>

#include "render/atmosphere.h"
#include "render/bsdf.h"
#include "render/camera.h"
#include "render/clouds.h"
#include "render/light_shafts.h"
#include "render/object_ids.h"
#include "render/physical_sky.h"
#include "render/random.h"
#include "render/render_settings.h"
#include "render/sky_sampler.h"
#include "render/terrain_scene.h"

namespace drift::render {

// Radiance of the simple sky in direction `dir` (unit, world z up); the sun's
// disc is not included (the sun is sampled explicitly).
Eigen::Vector3f sky_radiance(const Sky& sky, const Eigen::Vector3f& dir);

// What one camera sample brings back: radiance and the first hit's AOVs.
struct PixelSample {
  Eigen::Vector3f radiance{0, 0, 0};
  bool hit = false;                   // the camera ray met something
  float depth = 0.0f;                 // along the view axis (the EXR's Z)
  Eigen::Vector3f position{0, 0, 0};  // the hit, local frame
  int object = -1;                    // -1 sky, 0 terrain, k + 1 object k (render/mattes.h)
  Eigen::Vector3f normal{0, 0, 0};
  Eigen::Vector3f albedo{0, 0, 0};
  Coverage coverage{};  // by TerrainScene::coverage_names()
  float sky = 0.0f;     // 1 where the camera sees the sky
};

class PathTracer {
 public:
  // The sun, the sky and the air of a frame, precomputed for this camera.
  PathTracer(const TerrainScene& scene, const SceneInput& input, const CameraRays& camera,
             const RenderSettings& settings);
  ~PathTracer();
  PathTracer(const PathTracer&) = delete;
  PathTracer& operator=(const PathTracer&) = delete;

  // One sample of pixel (px, py), drawing from `rng`; adds the rays it
  // traced to `rays`.
  PixelSample trace(int px, int py, SampleStream& rng, std::uint64_t& rays) const;
  // n (1 to kCoherentSamples) samples of pixel (px, py) at once, sample i
  // drawing from rngs[i] into out[i]: the same as n calls of trace() but
  // for the camera rays, traced together (TerrainScene::intersect_coherent).
  static constexpr int kCoherentSamples = TerrainScene::kCoherentRays;
  void trace_coherent(int px, int py, SampleStream* rngs, int n, PixelSample* out,
                      std::uint64_t& rays) const;

 private:
  // A path under way: the ray leaving its last vertex and what it carries.
  struct Path {
    Eigen::Vector3f origin, dir;
    Eigen::Vector3f throughput{1, 1, 1};
    RayCone cone;
    float bounce_pdf = 0.0f;    // density of the BSDF sample that led here
    float shaft_jitter = 0.0f;  // light shafts' stratum offset for the camera ray
  };

  Path camera_path(int px, int py, SampleStream& rng) const;
  // The rest of trace() from vertex `first` on, its hit known (found: the
  // ray met something): the path's light added to `out`.
  void follow(Path& path, Hit& hit, bool found, SampleStream& rng, PixelSample& out,
              std::uint64_t& rays, int first) const;
  // A vertex's steps: the air (and clouds) the path crossed to reach it and
  // the first hit's AOVs (false: the path ends here, at max_depth); then,
  // after the sun, the sky's sample and the bounce (false: the path ends).
  bool arrive(Path& path, const Hit& hit, int depth, PixelSample& out, std::uint64_t& rays) const;
  bool leave(Path& path, const Hit& hit, const Eigen::Vector3f& p, const GroundBsdf& bsdf,
             int depth, SampleStream& rng, PixelSample& out, std::uint64_t& rays) const;
  // The sun's sample direction `l` from (u1, u2), true if it needs a shadow
  // ray (above the surface); and its light once that ray found nothing.
  bool sun_ray(const Hit& hit, float u1, float u2, Eigen::Vector3f& l) const;
  void add_sun(const Path& path, const Hit& hit, const Eigen::Vector3f& p, const GroundBsdf& bsdf,
               const Eigen::Vector3f& l, PixelSample& out) const;
  Eigen::Vector3f sky_light(const Eigen::Vector3f& dir) const;
  Eigen::Vector3f shaft_loss(const Path& path, float distance, std::uint64_t& rays) const;
  // The cloud layer (render/clouds.h): what a ray from `origin` sees of the
  // sky `behind` the layer, and the layer's light and loss on a path that
  // crosses it before reaching `distance`; `rays` counts the shadow rays
  // towards the sun from a layer below the peaks (light_on_clouds).
  Eigen::Vector3f cloudy_sky(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir,
                             const Eigen::Vector3f& behind, bool from_camera, const RayCone& cone,
                             std::uint64_t& rays) const;
  void cross_clouds(Path& path, float distance, int depth, PixelSample& out,
                    std::uint64_t& rays) const;
  void init_clouds(const SceneInput& input);
  // The steps of trace(), each adding its light to `out`.
  void escape_to_sky(const Path& path, int depth, PixelSample& out, std::uint64_t& rays) const;
  void cross_air(Path& path, const Hit& hit, int depth, PixelSample& out,
                 std::uint64_t& rays) const;
  void sample_sun(const Path& path, const Hit& hit, const Eigen::Vector3f& p,
                  const GroundBsdf& bsdf, float u1, float u2, PixelSample& out,
                  std::uint64_t& rays) const;
  void sample_sky(const Path& path, const Hit& hit, const Eigen::Vector3f& p,
                  const GroundBsdf& bsdf, float u1, float u2, PixelSample& out,
                  std::uint64_t& rays) const;
  // Continues the path by the BSDF from `p`; false when it ends (absorbed or
  // by Russian roulette).
  bool bounce(Path& path, const Hit& hit, const Eigen::Vector3f& p, const GroundBsdf& bsdf,
              int depth, SampleStream& rng) const;

  const TerrainScene& scene_;
  const SceneInput& input_;
  const CameraRays& camera_;
  const RenderSettings& settings_;
  ObjectLocator objects_;  // which object a camera ray's first hit is on
  Eigen::Vector3f sun_dir_;
  float sun_cos_max_ = 1.0f;
  Eigen::Vector3f sun_irradiance_;
  bool sun_up_ = false;
  std::unique_ptr<Atmosphere> atmosphere_;
  std::unique_ptr<PhysicalSky> air_;  // none for the simple and the constant sky
  float base_altitude_ = 0.0f;        // local z 0 in metres above sea level
  bool shafts_ = false;
  ShadowSlab shadow_slab_{0.0f, 0.0f};
  float air_reach_ = 0.0f;
  std::optional<SkySampler> sky_sampler_;
  std::optional<CloudLayer> clouds_;
  CloudLight cloud_light_;
  float air_under_clouds_ = 1.0f;  // the layer's mean transmittance towards the sun
  float cloud_altitude_ = 0.0f;    // the layer's altitude in local z
  // The light on the layer at a crossing (the terrain's shadow where it
  // lies below the peaks), and the share of in-scattering left to the air
  // between local heights z0 and z1 beneath it.
  CloudLight light_on_clouds(const CloudCrossing& c, std::uint64_t& rays) const;
  float air_shade(float z0, float z1) const;
  float sun_penumbra_ = 0.0f;  // the sun disc's angular diameter (radians)
};

}  // namespace drift::render
