#include "render/light_shafts.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drift::render {

namespace {

// The part [t0, t1] of [0, ray.distance] whose points lie within the slab's
// heights; empty when t1 <= t0.
void clip_to_slab(const ShaftRay& ray, const ShadowSlab& slab, float& t0, float& t1) {
  t0 = 0.0f;
  t1 = ray.distance;
  const float oz = ray.origin.z(), dz = ray.dir.z();
  if (std::abs(dz) < 1e-12f) {
    if (oz < slab.bottom || oz > slab.top) t1 = -1.0f;
    return;
  }
  const float ta = (slab.bottom - oz) / dz, tb = (slab.top - oz) / dz;
  t0 = std::max(t0, std::min(ta, tb));
  t1 = std::min(t1, std::max(ta, tb));
}

}  // namespace

Eigen::Vector3f shaft_shadow_loss(const PhysicalSky& air, float base_altitude, const ShaftRay& ray,
                                  const ShadowSlab& slab, int steps, float jitter,
                                  const std::function<bool(const Eigen::Vector3f&)>& in_shadow) {
  Eigen::Vector3f loss(0, 0, 0);
  float t0 = 0.0f, t1 = 0.0f;
  clip_to_slab(ray, slab, t0, t1);
  if (!(t1 > t0) || steps < 1) return loss;
  const float stratum = (t1 - t0) / static_cast<float>(steps);
  for (int i = 0; i < steps; ++i) {
    const float t = t0 + (static_cast<float>(i) + jitter) * stratum;
    const Eigen::Vector3f p = ray.origin + ray.dir * t;
    if (!in_shadow(p)) continue;
    const Eigen::Vector3f in_front = air.from_camera(ray.dir, t).transmittance;
    loss +=
        in_front.cwiseProduct(air.sun_single_scattering(base_altitude + p.z(), ray.dir, stratum));
  }
  return loss;
}

}  // namespace drift::render
