#include "dunes/wind_frame.h"

#include <cassert>
#include <cmath>
#include <numbers>

namespace drift::dunes {

WindFrame wind_frame(double wind_from_deg) {
  // The model's +x must point downwind (the azimuth the wind blows to); the
  // clockwise angle from east to there, in [0, 360).
  const double turn_deg = std::fmod(std::fmod(wind_from_deg + 180.0 - 90.0, 360.0) + 360.0, 360.0);
  const double quarters = std::round(turn_deg / 90.0);
  const double residual_deg = turn_deg - 90.0 * quarters;  // [-45, 45]
  WindFrame f;
  f.quarter_turns = static_cast<int>(quarters) % 4;
  // Quarter turns and diagonals given in degrees stay exact: sin 0 is 0,
  // not 1e-17, and sin / cos of 45 degrees is 1, not 0.9999999999999999
  // (which put every diagonal wind line a hair off the cell centres it runs
  // through and split each cell between two lines).
  if (std::fabs(residual_deg) < 1e-9) return f;
  if (std::fabs(std::fabs(residual_deg) - 45.0) < 1e-9) {
    f.cos_a = std::numbers::sqrt2 / 2.0;
    f.sin_a = std::copysign(f.cos_a, residual_deg);
    return f;
  }
  // Clockwise in map view with rows running south: +rows is clockwise of +x.
  const double a = residual_deg * std::numbers::pi / 180.0;
  f.cos_a = std::cos(a);
  f.sin_a = std::sin(a);
  return f;
}

terrain::HeightField turn_to_ground(const terrain::HeightField& m, const WindFrame& frame) {
  assert(m.width() == m.height() || frame.quarter_turns % 2 == 0);
  const int n = m.width(), rows = m.height();
  terrain::HeightField g(n, rows, 0.0f, m.geo());
  for (int row = 0; row < rows; ++row) {
    for (int x = 0; x < n; ++x) {
      // Ground (x, row) <- the model cell turned back by the quarter turns
      // (the inverse of one clockwise quarter: (x, r) <- (r, n - 1 - x)).
      int mx = x, mr = row;
      for (int t = 0; t < frame.quarter_turns; ++t) {
        const int px = mx;
        mx = mr;
        mr = n - 1 - px;
      }
      g(x, row) = m(mx, mr);
    }
  }
  return g;
}

}  // namespace drift::dunes
