#include "dunes/wind_frame.h"

#include <cassert>
#include <cmath>
#include <numbers>
#include <vector>

#include "dunes/lattice.h"

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
  // not 1e-17, and sin / cos of 45 degrees is 1, not 0.9999999999999999.
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

WindFrame wind_frame(double wind_from_deg, int n) {
  assert(n > 0);
  WindFrame f = wind_frame(wind_from_deg);
  // Rows per lap, nearest to n tan a (exact for the axes and diagonals,
  // whose tan wind_frame() keeps exact).
  f.shear = static_cast<int>(std::lround(n * f.rows_per_column()));
  if (f.shear == 0) {
    f.cos_a = 1.0;
    f.sin_a = 0.0;
  } else if (std::abs(f.shear) != n) {
    const double length = std::hypot(static_cast<double>(n), static_cast<double>(f.shear));
    f.cos_a = n / length;
    f.sin_a = f.shear / length;
  }
  return f;
}

double lattice_wind_from(double wind_from_deg, int n) {
  const WindFrame exact = wind_frame(wind_from_deg), rounded = wind_frame(wind_from_deg, n);
  // Clockwise residuals, so the wind comes from further clockwise by their
  // difference.
  const double shift =
      std::atan2(rounded.sin_a, rounded.cos_a) - std::atan2(exact.sin_a, exact.cos_a);
  return wind_from_deg + shift * 180.0 / std::numbers::pi;
}

terrain::HeightField unshear(const terrain::HeightField& s, int shear) {
  if (shear == 0) return s;
  const int n = s.width(), rows = s.height();
  // Cell (x, r) sits at lattice row r - shear x / n: `offset` rows (rounded
  // down) and `above` n-ths of a row from r, the same for a whole column.
  std::vector<int> offset(n);
  std::vector<double> w0(n), w1(n);
  for (int x = 0; x < n; ++x) {
    const long long shift = -static_cast<long long>(shear) * x;
    const long long down = floor_div(shift, n);
    const auto above = static_cast<int>(shift - down * n);
    offset[x] = wrap_index(static_cast<int>(down % rows), rows);
    w0[x] = static_cast<double>(n - above) / n;
    w1[x] = static_cast<double>(above) / n;
  }
  terrain::HeightField m(n, rows, 0.0f, s.geo());
  for (int r = 0; r < rows; ++r) {
    for (int x = 0; x < n; ++x) {
      const int row0 = r + offset[x] < rows ? r + offset[x] : r + offset[x] - rows;
      const int row1 = row0 + 1 == rows ? 0 : row0 + 1;
      m(x, r) = static_cast<float>(w0[x] * s(x, row0) + w1[x] * s(x, row1));
    }
  }
  return m;
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
