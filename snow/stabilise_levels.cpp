#include "snow/stabilise_levels.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace drift::snow {

namespace {

// m: snow a cell holds is bare ground below this (the stabilisation's 1 mm
// tolerance: films thinner than that never move).
constexpr double kFilm = 1e-3;

// A settled coarse level: its ground, its snow and the snow's change.
struct CoarseChange {
  const terrain::Grid<float>& ground;
  const terrain::Grid<double>& snow;
  terrain::Grid<double> change;
};

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

// The slope of a block's change along one axis, from the one-sided differences
// of the change towards the block before (`behind`) and after (`ahead`) it:
// the steeper of those that rise the way the settled coarse surface rises
// (`rise`, its difference across the block), else 0. The passes never move
// snow uphill, so the start errs on the side of snow held uphill: a block on
// a pile's flank takes its gain or keeps its snow on the side towards the
// apex, the apex blocks lean towards the apex (with the smaller, limited
// slope, 2 x 2 apex blocks of equal change stood flat, and an 8 x 8 tower
// ended 1.4 degrees flatter than repose), and what that leaves steeper than
// repose the grid's passes take down within the block.
double uphill_slope(double behind, double ahead, double rise) {
  const double b = behind * rise > 0.0 ? behind : 0.0, a = ahead * rise > 0.0 ? ahead : 0.0;
  return std::abs(a) > std::abs(b) ? a : b;
}

// Block (x, y) of the fine snow: its layer changed by change(x, y), linearly
// across the block, its volume exact to rounding (see the header).
void prolong_block(int x, int y, int fine_width, const CoarseChange& coarse,
                   std::vector<double>& s) {
  const terrain::Grid<double>& change = coarse.change;
  const int w = change.width(), h = change.height();
  auto clamped = [&](const auto& grid, int i, int j) {
    return grid(std::clamp(i, 0, w - 1), std::clamp(j, 0, h - 1));
  };
  auto at = [&](int i, int j) { return clamped(change, i, j); };
  auto surface = [&](int i, int j) {
    return double{clamped(coarse.ground, i, j)} + clamped(coarse.snow, i, j);
  };
  const double d = change(x, y);
  if (d == 0.0) return;  // a block the coarse level left alone keeps its snow
  // A quarter of the slope per coarse cell: the fine centres lie a quarter of
  // a coarse cell from the block's centre.
  const double gx = 0.25 * uphill_slope(d - at(x - 1, y), at(x + 1, y) - d,
                                        surface(x + 1, y) - surface(x - 1, y));
  const double gy = 0.25 * uphill_slope(d - at(x, y - 1), at(x, y + 1) - d,
                                        surface(x, y + 1) - surface(x, y - 1));
  const auto c = block_cells(x, y, fine_width);
  const double volume = block_volume(s, c) + 4.0 * d;
  bool loses_more_than_held = false;
  for (std::size_t i : c) loses_more_than_held = loses_more_than_held || s[i] + d < 0.0;
  if (loses_more_than_held) {
    // A block whose whole mean moved (a pile's edge over bare cells, see the
    // header) gives in proportion to what each cell holds.
    const double held = block_volume(s, c);
    const double factor = held > 0.0 ? std::max(volume, 0.0) / held : 0.0;
    for (std::size_t i : c) s[i] *= factor;
  } else {
    const std::array<double, 4> offset{-gx - gy, gx - gy, -gx + gy, gx + gy};
    // s + d >= 0 in every cell, so with the offsets scaled to 0 no cell goes
    // negative: scale them just enough.
    double keep = 1.0;
    for (int k = 0; k < 4; ++k)
      if (offset[k] < 0.0 && s[c[k]] + d + offset[k] < 0.0)
        keep = std::min(keep, (s[c[k]] + d) / -offset[k]);
    for (int k = 0; k < 4; ++k) s[c[k]] = std::max(s[c[k]] + (d + keep * offset[k]), 0.0);
  }
  // The rounding residue to the deepest cell, so the block holds its volume.
  const double residue = volume - block_volume(s, c);
  std::size_t deepest = c[0];
  for (std::size_t i : c)
    if (s[i] > s[deepest]) deepest = i;
  s[deepest] = std::max(s[deepest] + residue, 0.0);
}

// True if every cell of block (x, y) holds more than a film of snow.
bool block_full(const std::vector<double>& s, int x, int y, int fine_width) {
  const auto c = block_cells(x, y, fine_width);
  return std::min({s[c[0]], s[c[1]], s[c[2]], s[c[3]]}) > kFilm;
}

// The snow of block (x, y) its coarse cell may move (see the header): the
// layer every cell holds, or the block's mean where its lowest surface is a
// bare cell and a neighbouring block is full.
double mobile_layer(const float* g, const std::vector<double>& s, int fine_width, int w, int h,
                    int x, int y, double mean_snow) {
  const auto c = block_cells(x, y, fine_width);
  const double layer = std::max(std::min({s[c[0]], s[c[1]], s[c[2]], s[c[3]]}), 0.0);
  if (layer > kFilm) return layer;
  std::size_t lowest = c[0];
  for (std::size_t i : c)
    if (g[i] + s[i] < g[lowest] + s[lowest]) lowest = i;
  if (s[lowest] > kFilm) return layer;  // snow in a hollow of the block stays
  for (int j = std::max(y - 1, 0); j <= std::min(y + 1, h - 1); ++j)
    for (int i = std::max(x - 1, 0); i <= std::min(x + 1, w - 1); ++i)
      if (block_full(s, i, j, fine_width)) return std::max(mean_snow, 0.0);
  return layer;
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
      const double layer = mobile_layer(g, s, fw, w, h, x, y, mean_snow);
      coarse.ground(x, y) = static_cast<float>(mean_ground + (mean_snow - layer));
      coarse.snow(x, y) = layer;
    }
  });
  return coarse;
}

void prolong_change(const terrain::Grid<float>& coarse_ground, const terrain::Grid<double>& before,
                    const terrain::Grid<double>& after, terrain::Grid<double>& snow) {
  CoarseChange coarse{coarse_ground, after, terrain::Grid<double>(after.width(), after.height())};
  for (std::size_t i = 0; i < coarse.change.size(); ++i)
    coarse.change.values()[i] = after.values()[i] - before.values()[i];
  const int fine_width = snow.width();
  tbb::parallel_for(0, after.height(), [&](int y) {
    for (int x = 0; x < after.width(); ++x) prolong_block(x, y, fine_width, coarse, snow.values());
  });
}

}  // namespace drift::snow
