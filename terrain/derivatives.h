// Surface derivatives of a height field: gradient, unit normals, slope and
// aspect, and a multi-resolution pyramid.
//
// The gradient is Horn's (1981) 3x3 weighted difference, the default of
// `gdaldem slope` and `gdaldem aspect`, so our rasters agree with GDAL's on the
// same DEM (tests/terrain/derivatives_test.cpp checks it cell by cell). Cell
// sizes come from the georeference (metres for a projected DEM); heights are in
// the same unit. Every valid cell gets a value: at the border the missing
// neighbours are extrapolated linearly and next to nodata they take the centre
// cell's height, as `gdaldem -compute_edges` does; nodata cells stay NaN.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "terrain/grid.h"

namespace drift::terrain {

// dz/dx (east) and dz/dy (north) of a cell, in height units per metre.
struct Gradient {
  float dzdx = 0.0f;
  float dzdy = 0.0f;
};

// Horn's gradient at cell (x, row); NaN components for a nodata cell.
Gradient horn_gradient(const HeightField& dem, int x, int row);

// Per-cell gradient, computed in parallel.
Grid<Gradient> gradient(const HeightField& dem);

// Unit upward normals (x east, y north, z up) of the surface z = dem * z_scale.
Grid<Eigen::Vector3f> normals(const HeightField& dem, float z_scale = 1.0f);

// Slope in degrees from horizontal, [0, 90). As `gdaldem slope`.
HeightField slope_degrees(const HeightField& dem);

// Aspect: the compass direction the slope faces (downhill), degrees clockwise
// from north in [0, 360). Flat cells have no aspect and are NaN (gdaldem writes
// its nodata value -9999 there). As `gdaldem aspect` on a north-up raster.
HeightField aspect_degrees(const HeightField& dem);

// A resolution pyramid: level 0 is `dem`, each next level halves both sizes
// (rounding up) by averaging the valid cells of each 2x2 block (NaN where all
// four are nodata), with the georeference's cell size doubled. Stops at a
// level whose longer side is at most `min_size` cells.
std::vector<HeightField> pyramid(const HeightField& dem, int min_size = 1);

// One pyramid step (exposed for tests and for other grids of floats).
HeightField halve(const HeightField& grid);

}  // namespace drift::terrain
