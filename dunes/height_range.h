// The lowest and highest value of a height field, by a vectorised parallel
// reduction (the flight and shadow bounds of every sand step need them).
#pragma once

#include "terrain/grid.h"

namespace drift::dunes {

struct HeightRange {
  float lo, hi;
};

// Exact (min and max do not round), so the same on any thread count. An
// empty field gives {+1e30, -1e30}.
HeightRange height_range(const terrain::HeightField& h);

}  // namespace drift::dunes
