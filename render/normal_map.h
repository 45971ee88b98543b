// A tileable bump map with level of detail: the slopes (dh/du, dh/dv) of a
// periodic height tile and a pyramid of their 2x2 box averages, sampled with
// the level chosen from the ray's footprint (trilinear, like mip-mapping).
//
// Slopes are stored rather than normals because slopes average linearly: the
// mean slope over a footprint is the slope of the mean surface, so a coarse
// level is exactly the average of the finer one and near and far pixels shade
// alike (no shimmer up close, no false flattening far away). The wind-ripple
// normal maps of paper 002 (256, 128, 64, 32 levels chosen per quad by
// distance) become this pyramid, with the level chosen per ray.
//
// Next to the slopes the pyramid keeps their second moment E[|g|^2], box
// filtered the same way (moments average linearly too), as LEAN mapping does
// (Olano & Baker 2010, "LEAN mapping"): at any footprint the variance
// E[|g|^2] - |E[g]|^2 is the relief the filter averaged away, which the
// renderer turns into roughness, so far ripples still darken and texture the
// sand's shading at low sun instead of vanishing.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "terrain/grid.h"

namespace drift::render {

class SlopePyramid {
 public:
  SlopePyramid() = default;
  // `tile` is periodic (opposite edges continue each other), heights and
  // `texel_metres` in metres. Throws drift::Error for an empty tile or NaN.
  SlopePyramid(const terrain::HeightField& tile, double texel_metres);

  bool empty() const { return levels_.empty(); }
  int levels() const { return static_cast<int>(levels_.size()); }
  double texel_metres() const { return texel_; }
  double tile_metres_x() const { return texel_ * levels_.front().width(); }
  double tile_metres_y() const { return texel_ * levels_.front().height(); }

  // Slope (dh/du, dh/dv) at tile coordinates (u east, v north, metres; the tile
  // repeats) averaged over a footprint `footprint_metres` wide.
  Eigen::Vector2f sample(double u, double v, double footprint_metres) const;
  // The same mean slope and the variance of the slopes within the footprint,
  // E[|g|^2] - |E[g]|^2 (>= 0): what the footprint does not resolve.
  struct Moments {
    Eigen::Vector2f slope{0, 0};
    float variance = 0.0f;
  };
  Moments sample_moments(double u, double v, double footprint_metres) const;
  // Bilinear slope of one level (tests).
  Eigen::Vector2f sample_level(int level, double u, double v) const;
  const terrain::Grid<Eigen::Vector2f>& level(int i) const { return levels_[i]; }
  // E[|g|^2] of level i's texels (tests).
  const terrain::Grid<float>& second_moment(int i) const { return second_[i]; }

 private:
  // The level of detail for a footprint: levels lo and lo + 1, blended by t.
  void choose_level(double footprint_metres, int& lo, float& t) const;

  std::vector<terrain::Grid<Eigen::Vector2f>> levels_;
  std::vector<terrain::Grid<float>> second_;
  double texel_ = 1.0;
};

// Halves a periodic grid by 2x2 box averages (odd sizes wrap around); for
// slopes (Eigen::Vector2f) and their second moments (float).
template <class T>
terrain::Grid<T> halve_periodic(const terrain::Grid<T>& level);

}  // namespace drift::render
