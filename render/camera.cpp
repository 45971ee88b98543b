#include "render/camera.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "terrain/error.h"

namespace drift::render {

namespace {

using Eigen::Vector3f;
constexpr float kPi = std::numbers::pi_v<float>;

}  // namespace

Vector3f CameraRays::direction(float x, float y) const {
  if (orthographic()) return forward;
  const float sx = (2.0f * x / static_cast<float>(width) - 1.0f) * tan_half * aspect;
  const float sy = (1.0f - 2.0f * y / static_cast<float>(height)) * tan_half;
  return (forward + right * sx + up * sy).normalized();
}

void CameraRays::ray(float x, float y, float u1, float u2, Vector3f& origin, Vector3f& dir) const {
  dir = direction(x, y);
  origin = eye;
  if (orthographic()) {  // parallel rays from the plane of the eye
    origin += right * ((2.0f * x / static_cast<float>(width) - 1.0f) * half_width) +
              up * ((1.0f - 2.0f * y / static_cast<float>(height)) * half_height);
    return;
  }
  if (lens_radius <= 0.0f) return;
  // Uniform point on the lens disc; the ray aims at where the pinhole ray
  // crosses the focal plane (distance focus_distance along `forward`).
  const float r = lens_radius * std::sqrt(u1), phi = 2.0f * kPi * u2;
  const Vector3f focus = eye + dir * (focus_distance / dir.dot(forward));
  origin = eye + right * (r * std::cos(phi)) + up * (r * std::sin(phi));
  dir = (focus - origin).normalized();
}

float CameraRays::footprint_width() const {
  return orthographic() ? 2.0f * half_height / static_cast<float>(height) : 0.0f;
}

float CameraRays::footprint_spread() const {
  return orthographic() ? 0.0f : 2.0f * tan_half / static_cast<float>(height);
}

float CameraRays::view_depth(const Vector3f& p) const { return (p - eye).dot(forward); }

std::array<float, 16> world_to_camera(const CameraRays& c, const Eigen::Vector3d& local_to_world) {
  // p_cam = R (p - eye) with R's rows right, up, forward; as a row vector
  // p_cam = p R^T - eye R^T.
  const Eigen::Vector3d eye = c.eye.cast<double>() + local_to_world;
  const Eigen::Vector3d axes[3] = {c.right.cast<double>(), c.up.cast<double>(),
                                   c.forward.cast<double>()};
  std::array<float, 16> m{};
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) m[4 * i + j] = static_cast<float>(axes[j][i]);
    m[12 + j] = static_cast<float>(-axes[j].dot(eye));
  }
  m[15] = 1.0f;
  return m;
}

std::array<float, 16> world_to_ndc(const CameraRays& c, const Eigen::Vector3d& local_to_world) {
  // Camera space to NDC, row-vector form: perspective x' = x / (2 t a) + z / 2,
  // y' = -y / (2 t) + z / 2, w = z (t = tan of half the vertical field, a the
  // aspect), so x'/w = 1/2 + x / (2 t a z); a map x' = x / (2 hw) + 1/2, w = 1.
  Eigen::Matrix4d projection = Eigen::Matrix4d::Zero();
  if (c.orthographic()) {
    projection(0, 0) = 0.5 / c.half_width;
    projection(1, 1) = -0.5 / c.half_height;
    projection(3, 0) = projection(3, 1) = 0.5;
    projection(3, 3) = 1.0;
    projection(2, 2) = 1.0;
  } else {
    const double t = c.tan_half, a = c.aspect;
    projection(0, 0) = 0.5 / (t * a);
    projection(1, 1) = -0.5 / t;
    projection(2, 0) = projection(2, 1) = 0.5;
    projection(2, 2) = 1.0;
    projection(2, 3) = 1.0;
  }
  const std::array<float, 16> w2c = world_to_camera(c, local_to_world);
  Eigen::Matrix4d camera;
  for (int i = 0; i < 16; ++i) camera(i / 4, i % 4) = w2c[static_cast<std::size_t>(i)];
  const Eigen::Matrix4d m = camera * projection;
  std::array<float, 16> out{};
  for (int i = 0; i < 16; ++i)
    out[static_cast<std::size_t>(i)] = static_cast<float>(m(i / 4, i % 4));
  return out;
}

namespace {

// Cubic Hermite between values a (at t0) and b (at t1) with slopes ma, mb
// (per second), at s in [0, 1] of the interval.
template <class T>
T hermite(const T& a, const T& b, const T& ma, const T& mb, double s, double dt) {
  const double s2 = s * s, s3 = s2 * s;
  return a * (2 * s3 - 3 * s2 + 1) + ma * (dt * (s3 - 2 * s2 + s)) + b * (-2 * s3 + 3 * s2) +
         mb * (dt * (s3 - s2));
}

// The Catmull-Rom slope at key i of values v: central difference over the
// neighbours' times, one-sided at the ends.
template <class T, class Get>
T slope(const std::vector<CameraKey>& keys, std::size_t i, Get get) {
  const std::size_t lo = i == 0 ? 0 : i - 1, hi = i + 1 == keys.size() ? i : i + 1;
  return (get(keys[hi]) - get(keys[lo])) * (1.0 / (keys[hi].time - keys[lo].time));
}

}  // namespace

Camera camera_at(const std::vector<CameraKey>& keys, double time, const Camera& base) {
  if (keys.empty()) throw Error("a camera path needs at least one keyframe");
  Camera c = base;
  c.projection = Projection::Perspective;
  auto at = [&](const CameraKey& k) {
    c.from = k.from;
    c.to = k.to;
    c.vertical_fov_deg = k.fov_deg;
    return c;
  };
  if (keys.size() == 1 || time <= keys.front().time) return at(keys.front());
  if (time >= keys.back().time) return at(keys.back());
  std::size_t i = 0;
  while (keys[i + 1].time < time) ++i;  // keys[i].time <= time < keys[i + 1].time
  const double dt = keys[i + 1].time - keys[i].time, s = (time - keys[i].time) / dt;
  auto from = [](const CameraKey& k) { return k.from; };
  auto to = [](const CameraKey& k) { return k.to; };
  auto fov = [](const CameraKey& k) { return k.fov_deg; };
  c.from = hermite<Eigen::Vector3d>(keys[i].from, keys[i + 1].from,
                                    slope<Eigen::Vector3d>(keys, i, from),
                                    slope<Eigen::Vector3d>(keys, i + 1, from), s, dt);
  c.to = hermite<Eigen::Vector3d>(keys[i].to, keys[i + 1].to, slope<Eigen::Vector3d>(keys, i, to),
                                  slope<Eigen::Vector3d>(keys, i + 1, to), s, dt);
  c.vertical_fov_deg =
      hermite<double>(keys[i].fov_deg, keys[i + 1].fov_deg, slope<double>(keys, i, fov),
                      slope<double>(keys, i + 1, fov), s, dt);
  return c;
}

}  // namespace drift::render
