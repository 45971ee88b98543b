// Degrees and radians: the one home of the conversion. Users and files speak
// degrees (azimuths, repose angles, fields of view); the maths wants radians.
// Both are computed as (x * pi) / 180 and (x * 180) / pi in the argument's own
// type, as every call site did before it moved here, so no output changed.
#pragma once

#include <cmath>
#include <numbers>

namespace drift::terrain {

template <class T>
constexpr T radians(T degrees) {
  return degrees * std::numbers::pi_v<T> / T(180);
}

template <class T>
constexpr T degrees(T radians) {
  return radians * T(180) / std::numbers::pi_v<T>;
}

// The factors themselves, for code that multiplies by one rounded constant
// (a float shading path, a table of formulas in degrees).
template <class T>
inline constexpr T kRadiansPerDegree = static_cast<T>(std::numbers::pi / 180.0);
template <class T>
inline constexpr T kDegreesPerRadian = static_cast<T>(180.0 / std::numbers::pi);

// The tangent of an angle given in degrees (slopes from repose angles).
template <class T>
T tan_degrees(T degrees_) {
  return std::tan(radians(degrees_));
}

}  // namespace drift::terrain
