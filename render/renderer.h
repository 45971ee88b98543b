// The path tracer: unidirectional, with next-event estimation of the sun and
// of the importance-sampled sky (render/sky_sampler.h), BSDF-sampled bounces
// (render/bsdf.h: rough diffuse ground with a wet coat) whose escapes to the
// sky are weighed against the sky's samples by multiple importance sampling,
// and Russian roulette. Pixels are independent and their random numbers
// counter-based, so the image is the same bits for any thread count and tile
// order.
#pragma once

#include <cstdint>

#include "render/image.h"
#include "render/render_settings.h"
#include "render/terrain_scene.h"
#include "terrain/progress.h"

namespace drift::render {

// The camera used when a scene names none: from above the DEM's southern edge,
// looking north at its highest point.
Camera default_camera(const TerrainScene& scene);

// The primary rays of a camera in the scene's local frame (z up; straight up
// or down keeps north as "up" in the image): a pinhole, or a thin lens with
// depth of field when lens_radius > 0 (Pharr et al., PBRT 3rd ed., 6.2.3).
struct CameraRays {
  Eigen::Vector3f eye, forward, right, up;
  float tan_half = 0.0f, aspect = 1.0f;  // tan of half the vertical field of view
  int width = 1, height = 1;
  float lens_radius = 0.0f;     // metres
  float focus_distance = 1.0f;  // metres along `forward`
  // Unit direction of the pinhole ray through image position (x, y) in pixels,
  // (0, 0) top left.
  Eigen::Vector3f direction(float x, float y) const;
  // The ray through (x, y) from lens position (u1, u2) in [0, 1)^2 (ignored
  // for a pinhole): all rays through one image point meet on the focal plane.
  void ray(float x, float y, float u1, float u2, Eigen::Vector3f& origin,
           Eigen::Vector3f& dir) const;
};
CameraRays make_camera_rays(const TerrainScene& scene, const Camera& camera, int width, int height);

// Radiance of the simple sky in direction `dir` (unit, world z up); the sun's
// disc is not included (the sun is sampled explicitly).
Eigen::Vector3f sky_radiance(const Sky& sky, const Eigen::Vector3f& dir);

// Counts of the work a render did (for benchmarks and logs).
struct RenderStats {
  std::uint64_t camera_rays = 0;  // the samples taken (fewer than spp x pixels if adaptive)
  std::uint64_t rays = 0;         // all intersection and shadow rays
};

// Renders channels R, G, B (linear radiance) and AOVs "depth" (metres along
// the camera ray to the first hit, 0 for sky), "normal.X/Y/Z" and
// "albedo.R/G/B" and "coverage.<name>" (each ground material's share, the last
// "coverage.snow"; render/coverage.h) of the first hit, and "mask.sky"
// (the share of the pixel's camera rays that see the sky); with a noise
// target also "samples" (the samples the pixel took). `camera` is in the raster's CRS.
Image render_image(const TerrainScene& scene, const SceneInput& input, const Camera& camera,
                   const RenderSettings& settings, const ProgressFn& progress = no_progress,
                   RenderStats* stats = nullptr);

}  // namespace drift::render
