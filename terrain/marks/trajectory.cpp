#include "terrain/marks/trajectory.h"

#include <algorithm>
#include <cmath>

#include "terrain/angles.h"
#include "terrain/error.h"

namespace drift::marks {

Eigen::Quaterniond rotation_from_ypr(double yaw_deg, double pitch_deg, double roll_deg) {
  const double k = terrain::kRadiansPerDegree<double>;
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw_deg * k, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(-pitch_deg * k, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(roll_deg * k, Eigen::Vector3d::UnitX()));
}

void Trajectory::validate(const std::string& what) const {
  if (keys.empty()) throw Error(what + ": an object needs at least one keyframe");
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const Keyframe& k = keys[i];
    const std::string where = what + ": keyframe " + std::to_string(i + 1);
    if (!std::isfinite(k.time) || !k.position.allFinite() || !k.rotation.coeffs().allFinite())
      throw Error(where + " holds a value that is not a finite number");
    if (std::abs(k.rotation.norm() - 1.0) > 1e-6)
      throw Error(where + ": the rotation quaternion is not of unit length");
    if (i > 0 && !(k.time > keys[i - 1].time)) {
      throw Error(where + " is at time " + std::to_string(k.time) +
                  " s, not after the keyframe before it (" + std::to_string(keys[i - 1].time) +
                  " s); list keyframes in increasing time");
    }
  }
}

Pose Trajectory::at(double t) const {
  if (t <= keys.front().time) return {keys.front().position, keys.front().rotation};
  if (t >= keys.back().time) return {keys.back().position, keys.back().rotation};
  const auto next = std::upper_bound(keys.begin(), keys.end(), t,
                                     [](double v, const Keyframe& k) { return v < k.time; });
  const Keyframe& b = *next;
  const Keyframe& a = *(next - 1);
  const double s = (t - a.time) / (b.time - a.time);
  return {a.position + s * (b.position - a.position), a.rotation.slerp(s, b.rotation)};
}

}  // namespace drift::marks
