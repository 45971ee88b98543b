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

// Wind lines: line j runs through (x, j + t x) for every column x, t the rows
// crossed per column (sin a / cos a, in [-1, 1]); the field is sampled on it
// by linear interpolation between the two rows around it. Per line j and
// column x, at [j * width + x]: bit 0 set if that sample is shadowed; the rest
// (value >> 1) the columns to the first shadowed sample downwind on the line,
// at most min(width, ceil(max_columns) + 1) (none that near). For t = 0 lines
// are rows.
//
// Exact lines rather than digital (staircase) ones: a crest oblique to the
// grid then casts the same shadow on every line, and dunes keep crests across
// the wind instead of snapping to the grid's axes.
using ShadowMap = std::vector<std::uint16_t>;

// `drop_per_cell` (> 0): the shadow line's fall per cell of distance along
// the wind, in height units. `max_columns`: the longest flight in columns;
// distances beyond it are not needed. Lines are followed from as far upwind
// as a shadow can reach (across the periodic edge) to that far downwind;
// they are independent, so the result is the same for any thread count.
// `recovery` (if not null): also the lift's recovery past shadows (see
// shadow_recovery()) with ratio `recovery_ratio`, worked out on the way. An
// oblique line does not close on itself after a lap, so its recovery at
// column 0 comes from the shadows of the line arriving there, followed back
// across the periodic edge.
void wind_shadow(const terrain::HeightField& h, double rows_per_column, double drop_per_cell,
                 double max_columns, ShadowMap& shadow, double recovery_ratio = 0.0,
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
// grid; wind_shadow() handles oblique lines).
void shadow_recovery(const ShadowMap& shadow, int width, double ratio,
                     std::vector<float>& recovery);

// The same for one line of the map that closes on itself (a row, for a wind
// along the grid): `line` its `width` samples, `out` as many.
void line_recovery(const std::uint16_t* line, int width, double ratio, float* out);

inline bool shadowed(std::uint16_t s) { return (s & 1u) != 0; }
inline int columns_to_shadow(std::uint16_t s) { return s >> 1; }

// Where the wind lines cross column x (unwrapped): line j lies between rows
// j + row and j + row + 1, `frac` of the way.
struct Crossing {
  int row;
  double frac;
};
Crossing crossing(double rows_per_column, int x);

// The two wind lines around cell (x, row) given column x's crossing (its row
// taken modulo the field's rows, in [0, rows)), and the
// weight of the first, so that a cell and the line samples near it share
// weights the same way (linear interpolation and its adjoint). The second
// line's weight is 1 - weight_a; it is 0 for t = 0, where a cell's line is
// its row.
struct CellLines {
  int line_a, line_b;
  double weight_a;
};
inline CellLines cell_lines(const Crossing& c, int row, int rows) {
  // Line row - c.row passes c.frac below the cell, the one before it
  // 1 - c.frac above.
  const int a = row >= c.row ? row - c.row : row - c.row + rows;
  return {a, a == 0 ? rows - 1 : a - 1, 1.0 - c.frac};
}

}  // namespace drift::dunes
