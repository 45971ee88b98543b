// The path tracer: unidirectional, with next-event estimation of the sun,
// cosine-weighted bounces that gather the sky, Lambertian surfaces and Russian
// roulette. Pixels are independent and their random numbers counter-based, so
// the image is the same bits for any thread count and tile order.
#pragma once

#include "render/image.h"
#include "render/render_settings.h"
#include "render/terrain_scene.h"
#include "terrain/progress.h"

namespace drift::render {

// The camera used when a scene names none: from above the DEM's southern edge,
// looking north at its highest point.
Camera default_camera(const TerrainScene& scene);

// Radiance of the simple sky in direction `dir` (unit, world z up); the sun's
// disc is not included (the sun is sampled explicitly).
Eigen::Vector3f sky_radiance(const Sky& sky, const Eigen::Vector3f& dir);

// Renders channels R, G, B (linear radiance) and AOVs "depth" (metres along
// the camera ray to the first hit, 0 for sky), "normal.X/Y/Z" and
// "albedo.R/G/B" of the first hit. `camera` is in the raster's CRS.
Image render_image(const TerrainScene& scene, const SceneInput& input, const Camera& camera,
                   const RenderSettings& settings, const ProgressFn& progress = no_progress);

}  // namespace drift::render
