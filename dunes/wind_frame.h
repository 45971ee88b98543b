// The model's frame for a wind from any azimuth on a periodic square grid.
//
// The ground grid is north up (x east, rows south). A wind from any azimuth is
// split into an exact quarter turn of the grid and a residual angle of at most
// 45 degrees: the model runs on the grid turned by the quarter turns, with the
// wind blowing along (cos a, sin a) (columns, rows) there. Quarter turns of a
// periodic square grid are exact permutations of its cells, so the result is
// tileable for every azimuth, and azimuths 90 degrees apart give exactly
// turned fields; the residual keeps the wind's component along +x at least
// cos 45 degrees, so every flight moves downwind column by column.
//
// The wind lattice. On an n x n grid the residual is rounded to a whole number
// of rows per lap of columns, `shear` = k (t = k / n rows per column, within
// half a row per lap of the asked direction). The model's sand then lives on
// the sheared lattice whose rows are the wind lines: lattice point (i, j) sits
// at (i, j + t i) on the model grid, so every line runs exactly through its
// points, each point lies on one line, and flights, the wind shadow and the
// launch slope are one-dimensional along rows, as for a wind along x. The
// lattice is periodic with the grid: past column n - 1, row j goes on as row
// j + k from column 0 (a helix). Nothing depends on the column but through
// that wrap, so no pattern locks to the grid's columns, as it did when the
// lines were sampled between grid rows every step (docs/dunes.md). For k = 0
// the lattice is the grid; for k = +-n its rows are the grid's diagonals.
#pragma once

#include "terrain/grid.h"

namespace drift::dunes {

struct WindFrame {
  int quarter_turns = 0;  // clockwise quarter turns (map view) from model to ground
  double cos_a = 1.0;     // wind direction in the model grid: columns ...
  double sin_a = 0.0;     // ... and rows (rows run south before the turn), |a| <= 45 deg
  int shear = 0;          // wind_frame(az, n): rows per lap of n columns, |shear| <= n
  // Rows crossed per column along the wind: sin a / cos a, in [-1, 1].
  double rows_per_column() const { return sin_a / cos_a; }
};

// `wind_from_deg`: where the wind comes from, clockwise from north; the
// residual angle exact, shear 0.
WindFrame wind_frame(double wind_from_deg);

// The same on an n x n grid, the residual rounded to the wind lattice's
// t = shear / n (cos a and sin a those of the rounded direction).
WindFrame wind_frame(double wind_from_deg, int n);

// The azimuth the wind lattice of wind_frame(wind_from_deg, n) simulates:
// wind_from_deg moved by the rounding of its residual angle.
double lattice_wind_from(double wind_from_deg, int n);

// Wind lattice -> model grid (see above): each grid cell (x, r) by linear
// interpolation between the lattice points of column x around it, rows
// r - t x rounded down and up (weights exact multiples of 1/n). Column sums,
// so mass, are kept to float rounding; the identity for shear 0, a
// permutation of cells for shear +-n.
terrain::HeightField unshear(const terrain::HeightField& lattice, int shear);

// Model field -> ground field by the frame's quarter turns (exact; square
// grids). Values are copied unchanged.
terrain::HeightField turn_to_ground(const terrain::HeightField& model_field,
                                    const WindFrame& frame);

}  // namespace drift::dunes
