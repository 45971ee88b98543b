// Cameras and frame settings the render tests set up again and again.
#pragma once

#include <Eigen/Core>

#include "render/camera.h"
#include "render/render_settings.h"
#include "render/terrain_scene.h"

namespace drift::testing {

// A camera at `from` looking at `to`, both relative to the scene's origin.
inline render::Camera camera_from_to(const render::TerrainScene& scene, const Eigen::Vector3d& from,
                                     const Eigen::Vector3d& to, double vertical_fov_deg = 40.0) {
  render::Camera c;
  c.from = scene.origin() + from;
  c.to = scene.origin() + to;
  c.vertical_fov_deg = vertical_fov_deg;
  return c;
}

// A frame of `width` x `height` pixels at `spp` samples a pixel.
inline render::RenderSettings frame_settings(int width, int height, int spp) {
  render::RenderSettings rs;
  rs.width = width;
  rs.height = height;
  rs.samples_per_pixel = spp;
  return rs;
}

}  // namespace drift::testing
