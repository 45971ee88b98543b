// The wind shadow of a periodic height field on the wind lattice, the wind
// along its rows (after Werner 1995, "Eolian dunes: computer
// simulations and attractor interpretation", Geology 23:1107; paper 002 has
// none). The lee of a crest below a line falling at the shadow angle from it,
// downwind, is out of the wind: no sand is lifted there and grains flying into
// it are caught.
#pragma once

#include <cstdint>
#include <vector>

#include "dunes/height_range.h"
#include "terrain/grid.h"

namespace drift::dunes {

// Wind lines are the rows of the wind lattice (dunes/wind_frame.h), each
// closed on itself. Per lattice point (row j, column x), at [j * width + x]:
// bit 0 set if it is shadowed; the rest (value >> 1) the columns to the
// first shadowed point downwind on its row, at most min(width,
// ceil(max_columns) + 1) (none that near).
using ShadowMap = std::vector<std::uint16_t>;

// `range`: the field's height_range() (a caller that needs it too works it
// out once). `drop_per_column` (> 0): the shadow line's fall per column, in
// height units. `max_columns`: the longest flight in columns; distances
// beyond it are not needed. Rows are followed from as far upwind as a
// shadow can reach (across the periodic edge; the range bounds it) to that
// far downwind; they are independent, so the result is the same for any
// thread count.
void wind_shadow(const terrain::HeightField& h, HeightRange range, double drop_per_column,
                 double max_columns, ShadowMap& shadow);

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
// `shadow` as wind_shadow() filled it; each line closes on itself.
void shadow_recovery(const ShadowMap& shadow, int width, double ratio,
                     std::vector<float>& recovery);

// The same for one line of the map: `line` its `width` samples, `out` as
// many.
void line_recovery(const std::uint16_t* line, int width, double ratio, float* out);

// The only decoders of a ShadowMap entry (int, so that the vectorised
// flight kernels keep their integer arithmetic).
inline bool shadowed(int s) { return (s & 1) != 0; }
inline int lit(int s) { return ~s & 1; }  // 1 where the wind reaches, 0 in a shadow
inline int columns_to_shadow(int s) { return s >> 1; }

}  // namespace drift::dunes
