#include "snow/stabilise_levels.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace drift::snow {

namespace {

// The four fine cells of coarse cell (x, y), in row order.
std::array<std::size_t, 4> block_cells(int x, int y, int fine_width) {
  const std::size_t top = static_cast<std::size_t>(2 * y) * fine_width + 2 * x;
  const std::size_t bottom = top + fine_width;
  return {top, top + 1, bottom, bottom + 1};
}

// The block's volume in fine cells, summed in one fixed order.
double block_volume(const std::vector<double>& s, const std::array<std::size_t, 4>& c) {
  return (s[c[0]] + s[c[1]]) + (s[c[2]] + s[c[3]]);
}

// The smaller slope if both have the same sign, else 0 (no new extremes).
double minmod(double a, double b) {
  if (a * b <= 0.0) return 0.0;
  return std::abs(a) < std::abs(b) ? a : b;
}

// Block (x, y) of the fine snow: its layer changed by change(x, y), linearly
// across the block, its volume exact to rounding (see the header).
void prolong_block(int x, int y, int fine_width, const terrain::Grid<double>& change,
                   std::vector<double>& s) {
  const int w = change.width(), h = change.height();
  auto at = [&](int i, int j) { return change(std::clamp(i, 0, w - 1), std::clamp(j, 0, h - 1)); };
  const double d = change(x, y);
  // A quarter of the slope per coarse cell: the fine centres lie a quarter of
  // a coarse cell from the block's centre.
  const double gx = 0.25 * minmod(at(x + 1, y) - d, d - at(x - 1, y));
  const double gy = 0.25 * minmod(at(x, y + 1) - d, d - at(x, y - 1));
  if (d == 0.0 && gx == 0.0 && gy == 0.0) return;
  const auto c = block_cells(x, y, fine_width);
  const std::array<double, 4> offset{-gx - gy, gx - gy, -gx + gy, gx + gy};
  // d >= -(the layer every cell holds), so with the offsets scaled to 0 no
  // cell goes negative: scale them just enough.
  double keep = 1.0;
  for (int k = 0; k < 4; ++k)
    if (offset[k] < 0.0 && s[c[k]] + d + offset[k] < 0.0)
      keep = std::min(keep, std::max(s[c[k]] + d, 0.0) / -offset[k]);
  const double volume = block_volume(s, c) + 4.0 * d;
  for (int k = 0; k < 4; ++k) s[c[k]] = std::max(s[c[k]] + (d + keep * offset[k]), 0.0);
  // The rounding residue to the deepest cell, so the block holds its volume.
  const double residue = volume - block_volume(s, c);
  std::size_t deepest = c[0];
  for (std::size_t i : c)
    if (s[i] > s[deepest]) deepest = i;
  s[deepest] = std::max(s[deepest] + residue, 0.0);
}

}  // namespace

CoarseLevel restrict_to_coarse(const terrain::Grid<float>& ground,
                               const terrain::Grid<double>& snow) {
  const int w = snow.width() / 2, h = snow.height() / 2, fw = snow.width();
  CoarseLevel coarse{terrain::Grid<float>(w, h, 0.0f), terrain::Grid<double>(w, h, 0.0)};
  const float* g = ground.values().data();
  const std::vector<double>& s = snow.values();
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const auto c = block_cells(x, y, fw);
      const double mean_ground = 0.25 * ((static_cast<double>(g[c[0]]) + g[c[1]]) +
                                         (static_cast<double>(g[c[2]]) + g[c[3]]));
      const double mean_snow = 0.25 * block_volume(s, c);
      const double layer = std::max(std::min({s[c[0]], s[c[1]], s[c[2]], s[c[3]]}), 0.0);
      coarse.ground(x, y) = static_cast<float>(mean_ground + (mean_snow - layer));
      coarse.snow(x, y) = layer;
    }
  });
  return coarse;
}

void prolong_change(const terrain::Grid<double>& before, const terrain::Grid<double>& after,
                    terrain::Grid<double>& snow) {
  terrain::Grid<double> change(after.width(), after.height(), 0.0);
  for (std::size_t i = 0; i < change.size(); ++i)
    change.values()[i] = after.values()[i] - before.values()[i];
  const int fine_width = snow.width();
  tbb::parallel_for(0, after.height(), [&](int y) {
    for (int x = 0; x < after.width(); ++x) prolong_block(x, y, fine_width, change, snow.values());
  });
}

}  // namespace drift::snow
