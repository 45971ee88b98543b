// From linear scene radiance to display values: exposure in EV, a tone curve,
// and the sRGB transfer function.
#pragma once

namespace drift::render {

enum class ToneCurve {
  Filmic,  // smooth shoulder (ACES-like fit): highlights roll off, never clip hard
  Clamp,   // plain clamp to [0, 1] (for albedo and masks, and for tests)
};

struct DisplayTransform {
  double exposure_ev = 0.0;  // multiply radiance by 2^exposure_ev before the curve
  ToneCurve curve = ToneCurve::Filmic;
};

// Linear radiance -> display-linear value in [0, 1] (before the sRGB encoding).
float apply_tone_curve(float linear, const DisplayTransform& display);

// sRGB transfer function (IEC 61966-2-1) and its inverse, on [0, 1].
float srgb_encode(float display_linear);
float srgb_decode(float encoded);

}  // namespace drift::render
