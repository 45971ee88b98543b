// The 8 neighbours of a grid cell in the one order every 8-neighbour loop uses:
// row by row from (-1, -1) to (1, 1), so that neighbour k and neighbour 7 - k are
// opposite. Slope relaxation (terrain/slope_relax), snow's settling
// (snow/stabilise_grid) and marks' displacement (terrain/marks/displacement)
// share it: the order fixes the order of their sums, and so the bits of results
// that must agree between them.
#pragma once

#include <array>

namespace drift::terrain {

struct NeighbourOffset {
  int dx, dy;
};

inline constexpr std::array<NeighbourOffset, 8> kNeighbours8{
    {{-1, -1}, {0, -1}, {1, -1}, {-1, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}}};

// Neighbour k's opposite.
constexpr int opposite_neighbour(int k) { return 7 - k; }

}  // namespace drift::terrain
