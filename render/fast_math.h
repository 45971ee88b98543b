// Inverse trigonometric functions for the per-ray lookups (sky and air
// tables by direction, the sky sampler's density, a hit's slope, LEAN
// roughness): one arctangent kernel, Cephes' atanf (Moshier 1989), good to
// about 2e-7 rad, in place of libm's atan2f, asinf and acosf, which were
// 4-5 % of the default frame's paths (glibc's atan2f calls atanf again).
// Pure functions of their arguments, so images stay the same bits for any
// thread count.
#pragma once

#include <cmath>
#include <numbers>

namespace drift::render {

// atan(t) for t >= 0 (NaN stays NaN): reduced to |x| <= tan(pi/8) by
// atan t = pi/2 - atan(1/t) and atan t = pi/4 + atan((t - 1)/(t + 1)), then
// an odd polynomial of degree 9.
inline float fast_atan_positive(float t) {
  float x = t, base = 0.0f;
  if (t > 2.414213562373095f) {
    x = -1.0f / t, base = std::numbers::pi_v<float> / 2;
  } else if (t > 0.4142135623730950f) {
    x = (t - 1.0f) / (t + 1.0f), base = std::numbers::pi_v<float> / 4;
  }
  const float z = x * x;
  return base +
         (((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z -
          3.33329491539e-1f) *
             z * x +
         x;
}

// atan2(y, x) in [-pi, pi] (both zero: 0).
inline float fast_atan2(float y, float x) {
  constexpr float pi = std::numbers::pi_v<float>;
  const float ax = std::abs(x), ay = std::abs(y);
  if (ax == 0.0f && ay == 0.0f) return 0.0f;
  // The angle from the x axis in the first quadrant, from whichever ratio
  // is at most 1 (no overflow for any finite pair).
  float a = ay <= ax ? fast_atan_positive(ay / ax) : pi / 2 - fast_atan_positive(ax / ay);
  if (x < 0.0f) a = pi - a;
  return y < 0.0f ? -a : a;
}

// asin(z) and acos(z) for z in [-1, 1] (clamped), through the arctangent of
// z against sqrt(1 - z^2).
inline float fast_asin(float z) {
  z = std::fmax(-1.0f, std::fmin(z, 1.0f));
  return fast_atan2(z, std::sqrt((1.0f - z) * (1.0f + z)));
}
inline float fast_acos(float z) {
  z = std::fmax(-1.0f, std::fmin(z, 1.0f));
  return fast_atan2(std::sqrt((1.0f - z) * (1.0f + z)), z);
}

}  // namespace drift::render
