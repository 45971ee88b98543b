// Tone curves and the sRGB transfer function.
//
// Filmic curve: Krzysztof Narkowicz, "ACES Filmic Tone Mapping Curve" (2016),
// a rational fit of the ACES RRT+ODT:  f(x) = x(ax + b) / (x(cx + d) + e),
// a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14. f(0) = 0 and, for x >= 0,
// f'(x) has numerator 1.408x^2 + 0.7205x + 0.0042 > 0 (the x^3 terms cancel),
// so it is monotone; it passes 1 near x = 11 and tends to a/c = 1.033, so the
// clamp to [0, 1] only bites far into the highlights (a soft shoulder).
// sRGB: IEC 61966-2-1:1999, the piecewise curve with the 0.0031308 / 0.04045 split.
#include "render/tonemap.h"

#include <algorithm>
#include <cmath>

namespace drift::render {

namespace {

float clamp01(float v) {
  // NaN and negative radiance (never physical) display as black.
  if (!(v > 0.0f)) return 0.0f;
  return std::min(v, 1.0f);
}

float narkowicz_aces(float x) {
  constexpr float a = 2.51f, b = 0.03f, c = 2.43f, d = 0.59f, e = 0.14f;
  return (x * (a * x + b)) / (x * (c * x + d) + e);
}

}  // namespace

float apply_tone_curve(float linear, const DisplayTransform& display) {
  if (!(linear > 0.0f)) return 0.0f;
  const float x = linear * static_cast<float>(std::exp2(display.exposure_ev));
  switch (display.curve) {
    case ToneCurve::Filmic:
      if (std::isinf(x)) return 1.0f;
      return clamp01(narkowicz_aces(x));
    case ToneCurve::Clamp:
      return clamp01(x);
  }
  return clamp01(x);
}

double middle_grey_ev(ToneCurve curve) {
  constexpr double kGrey = 0.18;
  DisplayTransform display;
  display.curve = curve;
  // The curve is monotone (header comment): bisect for curve(x) = 0.18 in log2 x.
  double lo = -8.0, hi = 8.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    const float shown = apply_tone_curve(static_cast<float>(kGrey * std::exp2(mid)), display);
    (shown < kGrey ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

float srgb_encode(float v) {
  v = clamp01(v);
  // IEC 61966-2-1, eq. for the encoding (linear segment below 0.0031308).
  if (v <= 0.0031308f) return 12.92f * v;
  return 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

float srgb_decode(float e) {
  e = clamp01(e);
  if (e <= 0.04045f) return e / 12.92f;
  return std::pow((e + 0.055f) / 1.055f, 2.4f);
}

}  // namespace drift::render
