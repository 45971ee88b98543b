// Light shafts: the terrain's shadow on the air (docs/rendering.md, Sky, sun
// and air; issue 7's optional item). Aerial perspective
// (PhysicalSky::from_camera) lets the sun light all the air between the camera
// and what it sees; where a ridge hides the sun, that air scatters only the
// sky's light, and at a low sun dark shafts fall from the peaks through the
// haze.
//
// The camera ray is cut into `steps` equal strata within the heights where a
// shadow can be (between the scene's lowest and highest geometry); one point
// per stratum, at a jittered offset shared by all strata, is tested for the
// sun. Each point in shadow removes its stratum's single scattering of the
// sun, seen through the air in front of it (T(camera, s) times
// PhysicalSky::sun_single_scattering). Multiple scattering, lit by the whole
// sky, stays: a refinement of Bruneton's 2017 `shadow_length`, which drops all
// scattering along the shadowed length. Unbiased in the jitter for the
// stratified integral; the strata's noise averages out over a pixel's samples.
#pragma once

#include <Eigen/Core>
#include <functional>

#include "render/physical_sky.h"

namespace drift::render {

struct ShaftRay {
  Eigen::Vector3f origin;  // the camera, local coordinates
  Eigen::Vector3f dir;     // unit
  float distance;          // to the surface it hits, or the air's reach for the sky
};

// The heights (local z) that can be in the terrain's shadow.
struct ShadowSlab {
  float bottom, top;
};

// In-scattered radiance that the shadow takes out of `ray`'s aerial
// perspective (subtract it from PhysicalSky::from_camera's, or the sky's).
// `base_altitude` turns local z into metres above sea level; `jitter` in
// [0, 1); `in_shadow(p)` tells whether the sun is hidden from local point p.
Eigen::Vector3f shaft_shadow_loss(const PhysicalSky& air, float base_altitude, const ShaftRay& ray,
                                  const ShadowSlab& slab, int steps, float jitter,
                                  const std::function<bool(const Eigen::Vector3f&)>& in_shadow);

}  // namespace drift::render
