// Laying a height change on the ground (snow's depth, a stage's deposit): the
// one function and the one nodata rule every stage and the command line use.
// Where the ground has no data the result has none (NaN); where the change has
// none (NaN or infinite: a cell the stage did not reach), the ground stays as
// it is.
#pragma once

#include "terrain/grid.h"

namespace drift::terrain {

// ground + change, cell by cell, with the ground's georeference. Throws
// drift::Error naming `what` unless the two grids have the same size.
HeightField lay_on_ground(const HeightField& ground, const HeightField& change,
                          const char* what = "the height change");

}  // namespace drift::terrain
