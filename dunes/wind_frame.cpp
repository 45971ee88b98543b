#include "dunes/wind_frame.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <utility>

#include "dunes/lattice.h"

#include "terrain/angles.h"

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
  const double a = terrain::radians(residual_deg);
  f.cos_a = std::cos(a);
  f.sin_a = std::sin(a);
  return f;
}

namespace {

// (a, b) with b p - a q = 1 for coprime p > 0, q >= 0 (extended Euclid).
std::pair<long long, long long> unit_pair(long long p, long long q) {
  // Invariants: r0 = s0 p + t0 q, r1 = s1 p + t1 q.
  long long r0 = p, r1 = q, s0 = 1, s1 = 0, t0 = 0, t1 = 1;
  while (r1 != 0) {
    const long long k = r0 / r1;
    r0 = std::exchange(r1, r0 - k * r1);
    s0 = std::exchange(s1, s0 - k * s1);
    t0 = std::exchange(t1, t0 - k * t1);
  }
  // r0 = 1 = s0 p + t0 q: b = s0, a = -t0.
  return {-t0, s0};
}

// Rows a turned lattice has at least: rows are the steps' units of parallel
// work (the diagonal of the smallest grid, 8 cells, has 5).
constexpr int kMinRows = 4;

}  // namespace

WindLattice wind_lattice(double wind_from_deg, int n) {
  assert(n > 0);
  WindLattice l;
  l.frame = wind_frame(wind_from_deg);
  l.columns = l.rows = n;
  if (l.frame.sin_a == 0.0) return l;
  const double residual = std::atan2(std::fabs(l.frame.sin_a), l.frame.cos_a);  // (0, 45 deg]
  int best_p = 1, best_q = 1;
  if (std::fabs(l.frame.sin_a) != l.frame.cos_a) {  // not a diagonal
    // The axis itself is a candidate: the grid, exact, at the residual's
    // cost.
    double best = residual;
    best_q = 0;
    const double longest = std::max(std::numbers::sqrt2, std::sqrt(static_cast<double>(n)));
    for (int p = 1; p <= longest; ++p) {
      for (int q = 1; q <= p; ++q) {
        const double c = std::hypot(p, q);
        const int rows = static_cast<int>(n / c);
        if (c > longest || rows < kMinRows || std::gcd(p, q) != 1) continue;
        const double cost = std::fabs(std::atan2(q, p) - residual) + (n / (c * rows) - 1.0);
        if (cost < best) {
          best = cost;
          best_p = p;
          best_q = q;
        }
      }
    }
    if (best_q == 0) {  // the axis
      l.frame.cos_a = 1.0;
      l.frame.sin_a = 0.0;
      return l;
    }
  }
  const double c = std::hypot(best_p, best_q);
  l.p = best_p;
  l.q = l.frame.sin_a < 0.0 ? -best_q : best_q;
  l.rows = static_cast<int>(n / c);
  l.columns = (best_p * best_p + best_q * best_q) * l.rows;
  l.cell = n / (c * l.rows);
  // S = K (a p + b q) for b p - a q = 1; with q < 0, a mirrored.
  auto [a, b] = unit_pair(best_p, best_q);
  if (l.q < 0) a = -a;
  const long long turns = (a * l.p + b * l.q) % l.columns;
  l.shift = wrap_index(static_cast<int>(turns * l.rows % l.columns), l.columns);
  if (best_p == best_q) {  // the diagonal, as wind_frame() keeps it exact
    l.frame.cos_a = std::numbers::sqrt2 / 2.0;
    l.frame.sin_a = std::copysign(l.frame.cos_a, l.q);
  } else {
    l.frame.cos_a = l.p / c;
    l.frame.sin_a = l.q / c;
  }
  return l;
}

double lattice_wind_from(double wind_from_deg, int n) {
  const WindFrame exact = wind_frame(wind_from_deg);
  const WindFrame rounded = wind_lattice(wind_from_deg, n).frame;
  // Clockwise residuals, so the wind comes from further clockwise by their
  // difference.
  const double shift =
      std::atan2(rounded.sin_a, rounded.cos_a) - std::atan2(exact.sin_a, exact.cos_a);
  return wind_from_deg + terrain::degrees(shift);
}

terrain::HeightField lattice_to_grid(const terrain::HeightField& s, const WindLattice& l, int n) {
  if (!l.turned()) return s;
  assert(s.width() == l.columns && s.height() == l.rows);
  terrain::HeightField m(n, n, 0.0f, s.geo());
  const double along_x = l.frame.cos_a / l.cell, along_y = l.frame.sin_a / l.cell;
  double sum = 0.0;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      // The cell's lattice coordinates: (u, v) / h along and across the wind.
      const double i = x * along_x + y * along_y, j = -x * along_y + y * along_x;
      const double i0 = std::floor(i), j0 = std::floor(j);
      const double fi = i - i0, fj = j - j0;
      const auto ii = static_cast<long long>(i0), jj = static_cast<long long>(j0);
      auto at = [&](long long di, long long dj) {
        return static_cast<double>(lattice_at(s, ii + di, jj + dj, l.shift));
      };
      const double v = (1.0 - fj) * ((1.0 - fi) * at(0, 0) + fi * at(1, 0)) +
                       fj * ((1.0 - fi) * at(0, 1) + fi * at(1, 1));
      m(x, y) = static_cast<float>(v);
      sum += v;
    }
  }
  double lattice_sum = 0.0;
  for (const float v : s.values()) lattice_sum += v;
  const auto correction = static_cast<float>(lattice_sum / s.size() - sum / m.size());
  for (float& v : m.values()) v += correction;
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
