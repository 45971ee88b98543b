// From linear scene radiance to display values: exposure in EV, a tone curve,
// and the sRGB transfer function.
#pragma once

#include <array>

namespace drift::render {

enum class ToneCurve {
  Filmic,  // smooth shoulder (ACES-like fit): highlights roll off, never clip hard
  Clamp,   // plain clamp to [0, 1] (for albedo and masks, and for tests)
};

// A camera's "daylight" white balance: per-channel gains that make a white
// level surface at sea level, lit by the sun 60 degrees up and its sky in
// Bruneton's reference atmosphere (render/atmosphere.h), read neutral at the
// same luminance (linear sRGB, Rec. 709 luminance weights). That light is
// warmer than sRGB's D65 white, as photographers' "daylight" (about 5500 K)
// is; under it snow renders white rather than cream, and a setting sun still
// reddens. Checked against the atmosphere by tests/render/atmosphere_test.cpp.
inline constexpr std::array<float, 3> kDaylightWhiteBalance{0.9003f, 1.0252f, 1.0904f};

struct DisplayTransform {
  // A fixed exposure or a compensation lies in [-kMaxEv, kMaxEv] (scene file
  // and command line alike).
  static constexpr double kMaxEv = 20.0;

  double exposure_ev = 0.0;  // multiply radiance by 2^exposure_ev before the curve
  ToneCurve curve = ToneCurve::Filmic;
  std::array<float, 3> white_balance{1.0f, 1.0f, 1.0f};  // R, G, B gains before the curve
  // Meter each frame (render/auto_exposure.h) when it is written as PNG;
  // exposure_ev is then added to the metered exposure as a compensation.
  bool auto_exposure = false;
};

// The exposure (EV) under which `curve` displays a scene middle grey (0.18)
// at display-linear 0.18, i.e. sRGB code 118 of 255: a camera's standard
// output sensitivity (ISO 12232:2006, SOS: the exposure that puts an 18 %
// card at 118 in 8-bit sRGB). 0 for Clamp; about -0.47 EV for Filmic, whose
// toe and mid-tone lift would otherwise show the card at 0.267 (141 of 255)
// and every tone half a stop light. The meter adds it (render/image_io.h).
double middle_grey_ev(ToneCurve curve);

// Linear radiance -> display-linear value in [0, 1] (before the sRGB encoding).
float apply_tone_curve(float linear, const DisplayTransform& display);

// sRGB transfer function (IEC 61966-2-1) and its inverse, on [0, 1].
float srgb_encode(float display_linear);
float srgb_decode(float encoded);

}  // namespace drift::render
