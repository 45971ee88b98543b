// Automatic exposure by metering, as a camera's meter chooses it: the frame
// is exposed so that a grey card (reflectance 0.18) in the frame's typical
// light comes out at 0.18 before the tone curve (middle grey).
//
// When the image carries the render's AOVs (albedo.R/G/B and mask.sky) the
// meter reads the light, not the scene: every ground pixel's luminance over
// its albedo's is the light that falls there, as an incident-light meter
// held at that spot would read it (Ray 2002, "Applied Photographic Optics",
// 3rd ed., ch. 24: incident metering renders tones at their own reflectance,
// which is what a camera's snow compensation of +1 to +2 EV approximates).
// Snow so stays white (0.9 is 2.3 EV over grey) and dark rock dark, where a
// reflected-light meter would pull both to grey. The light is the
// centre-weighted upper quartile over the ground (weight exp(-r^2 / 2
// 0.35^2), r the distance from the centre over the half diagonal): the light
// of the sunlit ground, as a photographer takes an incident reading in the
// sun, so that shadows fall darker and not the other way round. With a depth
// channel only the nearer half of the ground (by depth) is read: the light
// held to the meter is the light where one stands, and far ground's radiance
// over its albedo counts the air's own light too (aerial perspective: dark
// forest 15 km off reads 2-3x the light of the sunlit ground in front, which
// pulled the default view's meter 0.4 EV dark). Without AOVs
// (or with under 1 % ground) the meter reads reflected light: the
// centre-weighted upper quartile of the luminance is taken to middle grey.
#pragma once

#include <array>

#include "render/image.h"

namespace drift::render {

struct Metering {
  double exposure_ev = 0.0;  // 2^ev multiplies the radiance before the tone curve
  double light = 0.0;        // the metered light (radiance of a white card), render units
  bool incident = false;     // true: from the albedo AOV (ground only); false: reflected
};

// Meters `linear` (channels R, G, B, optionally albedo.R/G/B, mask.sky, depth)
// after `white_balance`. A black frame meters to 0 EV. Throws drift::Error if
// the image has no R, G, B channels.
Metering meter_exposure(const Image& linear, const std::array<float, 3>& white_balance);

}  // namespace drift::render
