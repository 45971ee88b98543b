// Keyframed rigid motion of an object (paper 000, 3.2: objects are rigid and
// moved by the user): position and orientation at times, interpolated
// linearly in position and by slerp in rotation.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace drift::marks {

struct Keyframe {
  double time = 0.0;                  // s
  Eigen::Vector3d position{0, 0, 0};  // the object's origin (ground CRS metres)
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

// yaw: counter-clockwise about z seen from above; pitch: the object's +x end
// up; roll: about the object's +x axis (right-handed); degrees. Applied as
// R = Rz(yaw) Ry(-pitch) Rx(roll).
Eigen::Quaterniond rotation_from_ypr(double yaw_deg, double pitch_deg, double roll_deg);

struct Pose {
  Eigen::Vector3d position{0, 0, 0};
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

struct Trajectory {
  std::vector<Keyframe> keys;  // at least one, times strictly increasing

  // Throws drift::Error naming `what` for no keyframes, non-finite values, a
  // rotation that is not a rotation or times out of order.
  void validate(const std::string& what) const;
  double start() const { return keys.front().time; }
  double end() const { return keys.back().time; }
  bool active_at(double t) const { return t >= start() - 1e-9 && t <= end() + 1e-9; }
  // Linear position, slerp rotation; clamped to the first and last keyframe.
  Pose at(double t) const;
};

}  // namespace drift::marks
