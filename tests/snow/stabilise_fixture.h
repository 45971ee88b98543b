// What the stabilisation tests (snowfall_stabilise_test, stabilise_direct_test)
// share: the names of the solver's grid interface they both call, and the
// snow's total for the mass checks.
#pragma once

#include <numeric>

#include "snow/stabilise_grid.h"
#include "terrain/grid.h"

namespace drift::testing::stabilise {

using snow::max_repose_excess;
using snow::stabilise_grid;
using snow::StabiliseOptions;
using terrain::Grid;

// The snow's volume in cell-metres: what stabilisation conserves.
inline double total(const Grid<double>& g) {
  return std::accumulate(g.values().begin(), g.values().end(), 0.0);
}

}  // namespace drift::testing::stabilise
