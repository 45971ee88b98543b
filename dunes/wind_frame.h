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
// The wind lattice. On an n x n grid the residual is rounded to a direction
// (p, q) of whole columns and rows (p, q coprime, |q| <= p), and the sand
// lives on a square lattice turned to it, whose rows are the wind lines:
// lattice point (i, j) sits at i s (cos a, sin a) + j s (-sin a, cos a) on
// the model grid, s = n / (c K) grid cells apart (the spacing; `h` is the
// height field throughout dunes/), c = sqrt(p^2 + q^2),
// K = floor(n / c). The
// model grid is a torus (n x n, periodic), and so is the turned lattice when
// it has K rows of M = c^2 K points: a row closes on itself after M points
// (n (p, q) is a period of the grid), and past row K - 1, row 0 goes on
// `shift` columns back: point (i, j + K) is point (i - S, j), S = (a p + b q)
// K for b p - a q = 1. The lattice has as many points as the grid, within a
// row's worth.
//
// Every flight, the wind shadow and the launch slope run along a row, as
// for a wind along x, and a crest across the wind is a lattice column: no
// staircase, so slip faces across an oblique wind form as they do along the
// grid (a lattice sheared along the grid's columns wore them down,
// docs/dunes.md). The field is interpolated onto the grid at the end;
// for the axes the lattice is the grid itself (s = 1, S = 0, M = K = n).
#pragma once

#include "terrain/grid.h"

namespace drift::dunes {

struct WindFrame {
  int quarter_turns = 0;  // clockwise quarter turns (map view) from model to ground
  double cos_a = 1.0;     // wind direction in the model grid: columns ...
  double sin_a = 0.0;     // ... and rows (rows run south before the turn), |a| <= 45 deg
};

// `wind_from_deg`: where the wind comes from, clockwise from north; the
// residual angle exact.
WindFrame wind_frame(double wind_from_deg);

// The wind lattice of an n x n model grid (see above).
struct WindLattice {
  WindFrame frame;    // cos a, sin a those of (p, q)
  int p = 1, q = 0;   // the wind's direction in whole columns and rows
  int columns = 0;    // M = (p^2 + q^2) K points a row
  int rows = 0;       // K
  int shift = 0;      // S, in [0, M): past the last row, row 0 S columns back
  double cell = 1.0;  // s: the lattice's spacing in grid cells, in [1, 1 + 1 / K)
  bool turned() const { return q != 0; }
};

// The lattice for `wind_from_deg` on an n x n grid: of the axis and the
// directions (p, q) with c <= max(sqrt 2, sqrt n) (rows of at most
// max(2, sqrt n) grid widths: long thin lattices cost cache and parallel
// rows) and at least 4 rows, the one that minimises the angle from the wind
// (radians) plus s - 1 (a coarser lattice costs resolution: 1 % of it
// weighs as much as 0.57 degrees). The axes and diagonals are exact.
WindLattice wind_lattice(double wind_from_deg, int n);

// The azimuth the lattice of wind_lattice(wind_from_deg, n) simulates:
// wind_from_deg moved by the rounding of its residual angle.
double lattice_wind_from(double wind_from_deg, int n);

// Wind lattice -> n x n model grid: each grid cell bilinearly from the 4
// lattice points around it, then the mean (so the mass: the lattice's points
// stand for s^2 cells each, and M K s^2 = n^2) restored to float rounding.
// The lattice itself for a wind along the axes.
terrain::HeightField lattice_to_grid(const terrain::HeightField& lattice, const WindLattice& l,
                                     int n);

// Model field -> ground field by the frame's quarter turns (exact; square
// grids). Values are copied unchanged.
terrain::HeightField turn_to_ground(const terrain::HeightField& model_field,
                                    const WindFrame& frame);

}  // namespace drift::dunes
