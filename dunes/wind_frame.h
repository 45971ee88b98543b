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
#pragma once

#include "terrain/grid.h"

namespace drift::dunes {

struct WindFrame {
  int quarter_turns = 0;  // clockwise quarter turns (map view) from model to ground
  double cos_a = 1.0;     // wind direction in the model grid: columns ...
  double sin_a = 0.0;     // ... and rows (rows run south before the turn), |a| <= 45 deg
  // Rows crossed per column along the wind: sin a / cos a, in [-1, 1].
  double rows_per_column() const { return sin_a / cos_a; }
};

// `wind_from_deg`: where the wind comes from, clockwise from north.
WindFrame wind_frame(double wind_from_deg);

// Model field -> ground field by the frame's quarter turns (exact; square
// grids). Values are copied unchanged.
terrain::HeightField turn_to_ground(const terrain::HeightField& model_field,
                                    const WindFrame& frame);

}  // namespace drift::dunes
