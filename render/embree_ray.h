// An Embree ray-hit record for the nearest hit of a ray from o along d, at any
// distance, no hit yet: one set-up for every single-ray query.
#pragma once

#include <embree3/rtcore.h>

#include <Eigen/Core>
#include <limits>

namespace drift::render {

inline RTCRayHit nearest_ray_hit(const Eigen::Vector3f& o, const Eigen::Vector3f& d) {
  RTCRayHit rh{};
  rh.ray.org_x = o.x(), rh.ray.org_y = o.y(), rh.ray.org_z = o.z();
  rh.ray.dir_x = d.x(), rh.ray.dir_y = d.y(), rh.ray.dir_z = d.z();
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.mask = 0xffffffffu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

}  // namespace drift::render
