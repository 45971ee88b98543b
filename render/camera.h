// The camera: where it stands and how it projects (a pinhole or thin lens in
// perspective, or a map straight down), the primary rays it makes in a
// scene's local frame, and the matrices that tell other tools the same
// projection (OpenEXR's worldToCamera and worldToNDC).
//
// Its own header so that the path tracer (render/path_tracer.h) needs only
// the camera, not the renderer that drives it.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

namespace drift::render {

enum class Projection {
  Perspective,  // a pinhole, or a thin lens with depth of field
  Map,          // orthographic, straight down over `map_box`: a georeferenced map
};

struct Camera {
  Eigen::Vector3d from{0, 0, 0};  // world metres (x east, y north, z up)
  Eigen::Vector3d to{0, 1, 0};
  double vertical_fov_deg = 40.0;  // (0, 180)
  // A real lens instead of a field of view: the focal length gives the
  // horizontal field of view over the sensor's width (36 mm: full frame).
  std::optional<double> focal_length_mm;
  double sensor_width_mm = 36.0;
  // Depth of field: a thin lens of aperture diameter focal length / f_number,
  // sharp at focus_distance metres (default: the distance from `from` to
  // `to`). f_number 0 keeps a pinhole. Needs focal_length_mm.
  double f_number = 0.0;
  std::optional<double> focus_distance;
  // Projection::Map: the frame covers exactly this box of the CRS (west,
  // south, east, north, metres), looked at straight down from above every
  // geometry; pixel (0, 0)'s top-left corner is (west, north), as a GeoTIFF's
  // geotransform puts it. `from`, `to` and the lens are not used.
  Projection projection = Projection::Perspective;
  std::array<double, 4> map_box{0, 0, 1, 1};
};

// The primary rays of a camera in the scene's local frame (z up; straight up
// or down keeps north as "up" in the image): a pinhole, or a thin lens with
// depth of field when lens_radius > 0 (Pharr et al., PBRT 3rd ed., 6.2.3), or
// parallel rays straight down for a map.
struct CameraRays {
  Eigen::Vector3f eye, forward, right, up;  // a map's eye: the box's centre, above it all
  float tan_half = 0.0f, aspect = 1.0f;     // tan of half the vertical field of view
  int width = 1, height = 1;
  float lens_radius = 0.0f;     // metres
  float focus_distance = 1.0f;  // metres along `forward`
  // A map: the half sizes of the box in metres (0: perspective).
  float half_width = 0.0f, half_height = 0.0f;
  bool orthographic() const { return half_width > 0.0f; }
  // Unit direction of the pinhole ray through image position (x, y) in pixels,
  // (0, 0) top left.
  Eigen::Vector3f direction(float x, float y) const;
  // The ray through (x, y) from lens position (u1, u2) in [0, 1)^2 (ignored
  // for a pinhole and a map): all rays through one image point meet on the
  // focal plane.
  void ray(float x, float y, float u1, float u2, Eigen::Vector3f& origin,
           Eigen::Vector3f& dir) const;
  // A camera ray's footprint (render/terrain_scene.h, RayCone): metres wide
  // at its origin and per metre travelled; a pixel's angle, or a map's cell.
  float footprint_width() const;
  float footprint_spread() const;
  // Distance along the view axis from the eye (a map: from the plane of its
  // eye) to local point p: the EXR's Z.
  float view_depth(const Eigen::Vector3f& p) const;
};

// OpenEXR's standard attributes (OpenEXR/ImfStandardAttributes.h), as Imath stores
// them: row vectors, p' = p M, row-major. "World" is the scene's local frame
// shifted by `local_to_world` (world = local + local_to_world), so the
// numbers stay small. worldToCamera goes to RenderMan's camera space (x
// right, y up, z along the view, left-handed); worldToNDC to the display
// window's [0, 1]^2 (x right, y down) after division by w.
std::array<float, 16> world_to_camera(const CameraRays& camera,
                                      const Eigen::Vector3d& local_to_world);
std::array<float, 16> world_to_ndc(const CameraRays& camera, const Eigen::Vector3d& local_to_world);

}  // namespace drift::render

namespace drift::render {

// One key of a camera path ([[camera.keyframe]]): at `time` (seconds) the
// camera stands at `from`, looks at `to` (CRS metres) with a vertical field
// of view of `fov_deg`.
struct CameraKey {
  double time = 0.0;
  Eigen::Vector3d from{0, 0, 0}, to{0, 1, 0};
  double fov_deg = 40.0;
};

// The camera at `time` on the path through `keys` (sorted by time, at least
// one): a Catmull-Rom spline through the keys with tangents by central
// differences over the keys' own times (a C1 cubic Hermite; one-sided at
// the ends), for `from`, `to` and the field of view alike. It passes
// through every key, moves evenly along keys evenly spaced on a line, and
// holds the first or last key outside their times. `base` gives the lens.
Camera camera_at(const std::vector<CameraKey>& keys, double time, const Camera& base = {});

}  // namespace drift::render
