// The path tracer: unidirectional, with next-event estimation of the sun and
// of the importance-sampled sky (render/sky_sampler.h), BSDF-sampled bounces
// (render/bsdf.h: rough diffuse ground with a wet coat) whose escapes to the
// sky are weighed against the sky's samples by multiple importance sampling,
// and Russian roulette. Pixels are independent and their random numbers
// counter-based, so the image is the same bits for any thread count and tile
// order.
#pragma once

#include <cstdint>

#include "render/camera.h"
#include "render/image.h"
#include "render/render_settings.h"
#include "render/terrain_scene.h"
#include "terrain/progress.h"

namespace drift::render {

// Counts of the work a render did (for benchmarks and logs).
struct RenderStats {
  std::uint64_t camera_rays = 0;  // the samples taken (fewer than spp x pixels if adaptive)
  std::uint64_t rays = 0;         // all intersection and shadow rays
};

// Renders channels R, G, B (linear radiance) and the first hit's AOVs under
// the names compositors look for (docs/rendering.md, "EXR layers"): "Z"
// (metres along the view axis, 1e10 where nothing was hit), "N.X/Y/Z"
// (world normal), "albedo.R/G/B", "P.X/Y/Z" (the hit in the CRS less the
// header's worldOrigin), "coverage.<name>" (each ground material's share;
// render/coverage.h), "mask.sky" (the share of the pixel's camera rays that
// see the sky), with a noise target "samples" (the samples the pixel took),
// then the Cryptomatte layers CryptoMaterial00.. and CryptoObject00..
// (render/mattes.h). The header gets worldToCamera, worldToNDC, worldOrigin,
// crsWKT and the mattes' manifests. `camera` is in the raster's CRS.
Image render_image(const TerrainScene& scene, const SceneInput& input, const Camera& camera,
                   const RenderSettings& settings, const ProgressFn& progress = no_progress,
                   RenderStats* stats = nullptr);

}  // namespace drift::render
