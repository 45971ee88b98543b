// The wind shadow of a periodic height field for a wind along any direction
// within 45 degrees of +x (after Werner 1995, "Eolian dunes: computer
// simulations and attractor interpretation", Geology 23:1107; paper 002 has
// none). The lee of a crest below a line falling at the shadow angle from it,
// downwind, is out of the wind: no sand is lifted there and grains flying into
// it are caught.
#pragma once

#include <cstdint>
#include <vector>

#include "terrain/grid.h"

namespace drift::dunes {

// Wind lines are the rows of the wind lattice (dunes/wind_frame.h): line j
// runs along row j and, past the last column, on along row j + shear. Per
// lattice point (row j, column x), at [j * width + x]: bit 0 set if it is
// shadowed; the rest (value >> 1) the columns to the first shadowed point
// downwind on its line, at most min(width, ceil(max_columns) + 1) (none that
// near).
//
// Every point lies on one line, exactly: the shadow of a crest oblique to
// the grid is the same on every line, and nothing is interpolated between
// rows (which, at a fraction of a row changing from column to column, locked
// dunes to the grid's columns; docs/dunes.md).
using ShadowMap = std::vector<std::uint16_t>;

// `drop_per_cell` (> 0): the shadow line's fall per cell of distance along
// the wind, in height units (a column step is sqrt(1 + t^2) cells, t =
// shear / width). `max_columns`: the longest flight in columns; distances
// beyond it are not needed. Lines are followed from as far upwind as a
// shadow can reach (across the periodic edge) to that far downwind; they
// are independent, so the result is the same for any thread count.
// `recovery` (if not null): also the lift's recovery past shadows (see
// shadow_recovery()) with ratio `recovery_ratio`, worked out on the way. A
// sheared line does not close on itself after a lap, so its recovery at
// column 0 comes from the shadows of the line arriving there, followed back
// across the periodic edge.
void wind_shadow(const terrain::HeightField& h, int shear, double drop_per_cell, double max_columns,
                 ShadowMap& shadow, double recovery_ratio = 0.0,
                 std::vector<float>* recovery = nullptr);

// Beyond a shadow the wind does not take up sand at once: the flow
// reattaches behind the separation bubble and the sand flux then saturates
// over a distance (Kroy, Sauermann & Herrmann 2002, "Minimal model for sand
// dunes", PRL 88:054301, the saturation length; paper 002 and Werner 1995
// have neither). Per line sample, in the shadow map's layout: the share of
// the full lift the wind takes up there, rising linearly from 0 at the end
// of a shadow to 1 at `ratio` times that shadow's length (in samples) past
// it; 0 inside shadows, 1 on lines without any. A lift that jumps to full at
// the shadow's end scours a pit there whose downwind wall stands at the
// angle of repose facing the wind; the ramp keeps windward faces gentle.
// `shadow` as wind_shadow() filled it for the same field and lines; each line
// is taken to close on itself after a lap (true of rows, a wind along the
// grid; wind_shadow() handles sheared lines).
void shadow_recovery(const ShadowMap& shadow, int width, double ratio,
                     std::vector<float>& recovery);

// The same for one line of the map that closes on itself (a row, for a wind
// along the grid): `line` its `width` samples, `out` as many.
void line_recovery(const std::uint16_t* line, int width, double ratio, float* out);

inline bool shadowed(std::uint16_t s) { return (s & 1u) != 0; }
inline int columns_to_shadow(std::uint16_t s) { return s >> 1; }

}  // namespace drift::dunes
