// Rough test reliefs for the height-field tests: one home for a DEM drawn
// from a formula with noise, and for the relief the 16-bit heights quantise.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <random>

#include "terrain/grid.h"

namespace drift::testing {

// A DEM of w x h cells of `cell` m at UTM-sized coordinates (north-west
// corner at 600000 E, 4000000 N) with z(col, row, noise) at each cell, where
// `noise` is one draw in [-1, 1) a cell, in row order, from a generator
// seeded with `seed`.
template <class Z>
terrain::HeightField noisy_relief(int w, int h, double cell, unsigned seed, Z z) {
  terrain::HeightField dem(w, h, 0.0f, terrain::local_georeference(cell));
  dem.geo().geotransform[0] = 600000.0;
  dem.geo().geotransform[3] = 4000000.0;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> noise(-1.0f, 1.0f);
  for (int row = 0; row < h; ++row)
    for (int col = 0; col < w; ++col) dem(col, row) = z(col, row, noise(rng));
  return dem;
}

// The relief 16-bit heights are tested on, w cells wide: 500 m of long
// slopes, rough (8 m of noise) east of the middle and smooth (1 cm) west of
// it, where a block's step and a float's ulp are both visible; with
// `flat_corner` a flat 20 x 40 cells at the north-west (whole blocks of one
// height); a 300 m cliff down column 77, through blocks; 60 m spikes on a
// diagonal lattice.
inline float quantised_relief(int col, int row, int w, float noise, bool flat_corner) {
  float z = 900.0f + 500.0f * std::sin(col * 0.013f) * std::cos(row * 0.021f) +
            (col > w / 2 ? 8.0f * noise : 0.01f * noise);
  if (flat_corner && col < 20 && row < 40) z = 1234.5f;
  if (col == 77) z += 300.0f;
  if ((col * 7 + row * 13) % 101 == 0) z += 60.0f;
  return z;
}

// Calls fn(i, origin, direction) for `count` rays drawn with `seed`: origins
// at height z within +-spread of the scene's middle, going straight down, or
// with `tilt` > 0 leaning up to `tilt` (x and y of the direction before it
// is normalised) each way.
template <class Fn>
void random_rays(int count, unsigned seed, const Eigen::Vector2f& spread, float z, float tilt,
                 Fn fn) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3f o(u(rng) * spread.x(), u(rng) * spread.y(), z);
    Eigen::Vector3f d(0.0f, 0.0f, -1.0f);
    if (tilt > 0.0f) d = Eigen::Vector3f(u(rng) * tilt, u(rng) * tilt, -1.0f).normalized();
    fn(i, o, d);
  }
}

}  // namespace drift::testing
