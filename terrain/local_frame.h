// The local frame a height field is worked in: UTM-sized coordinates in float
// lose half a metre, so scenes (the renderer's Embree scene, the scene snow
// falls on) shift everything to an origin at the DEM's central cell and its
// lowest valid height, and keep the origin in double.
#pragma once

#include <Eigen/Core>
#include <string>

#include "terrain/grid.h"

namespace drift::terrain {

struct LocalFrame {
  Eigen::Vector3d origin{0, 0, 0};  // CRS position of the local origin (z: lowest height x z_scale)
  double x0 = 0, y0 = 0;            // local position of the centre of cell (0, 0), the NW corner
  float lowest = 0, highest = 0;    // valid (non-NaN) heights of the field, unscaled
};

// The frame of `dem` (north-up) with heights scaled by `z_scale` (vertical
// exaggeration): origin at the centre of the middle cell (between cells for an
// even size) and the lowest valid height. Throws drift::Error naming the field
// as `what` ("the terrain raster") if every cell is nodata.
LocalFrame local_frame(const HeightField& dem, const std::string& what, double z_scale = 1.0);

}  // namespace drift::terrain
