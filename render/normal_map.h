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
  // Bilinear slope of one level (tests).
  Eigen::Vector2f sample_level(int level, double u, double v) const;
  const terrain::Grid<Eigen::Vector2f>& level(int i) const { return levels_[i]; }

 private:
  std::vector<terrain::Grid<Eigen::Vector2f>> levels_;
  double texel_ = 1.0;
};

// Halves a periodic slope grid by 2x2 box averages (odd sizes wrap around).
terrain::Grid<Eigen::Vector2f> halve_periodic(const terrain::Grid<Eigen::Vector2f>& level);

}  // namespace drift::render
