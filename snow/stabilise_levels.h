// The coarse-to-fine start of snow stabilisation (snow/stabilise_grid.h): the
// field is settled first on grids of 2 x 2 blocks, coarsest first, and each
// level's change of snow is handed down to the next finer level as its start
// (nested iteration, as in full multigrid). The passes' slow mode is a
// diffusion (a slope at repose shifting in parallel takes O(L^2) passes for L
// cells), so a level of cells twice as large settles it in a quarter of the
// passes, each on a quarter of the cells; the finer level then has mostly its
// own detail left. Every level ends by the passes' own convergence criterion,
// the finest included, so whatever the start no pair is left steeper than
// repose. The passes only ever flatten and never move snow uphill, so the
// start must not leave a pile flatter than the grid's own passes would, nor
// snow lower than they would: the restriction and the hand-down below are
// chosen for that, and towers settle with their apex and flanks as with the
// passes alone (within 0.6 degrees; docs/snowfall.md). The state is not the
// passes' own (the benchmark field, one level: RMS 2.3 cm), which is why the
// start is an option (StabiliseOptions::coarse_levels, `--coarse-levels`).
//
// Restriction (a coarse cell is four fine cells; the caller doubles the cell
// size, so the repose drop per direction follows it):
//  - the coarse surface is the block's mean surface (ground + snow);
//  - the snow free to move (the coarse cell's snow) is the layer every cell of
//    the block holds; the rest of the block's snow counts as coarse ground.
//    Snow in a partly bare block (snow caught in a hollow, a column on its
//    own) stays where the fine passes left it, as a fine cell next to bare
//    ground gives only what it holds (with the whole block's mean free to
//    move, snow the fine ground holds in hollows smaller than a coarse cell was
//    carried off: at 1024^2 with four levels, 54 % of the ground covered
//    against 63 %). Except at a pile's edge: where a block's lowest surface is
//    a bare cell and a neighbouring block (8 around) is full, its whole mean
//    moves (the snow stands over bare ground beside a moving mass; held back,
//    a tower's half-bare edge blocks stood as a wall on the coarse level and
//    its flanks ended 1.9 degrees flatter);
//  - a grid of odd width or height leaves its last column or row out of the
//    coarse level, which is closed there like any edge; the finer level's
//    passes settle that strip.
// Prolongation, for each block the coarse level changed by d: its layer
// changes by d, tilted across the block towards where the settled coarse
// surface rises (the steeper of the one-sided differences of the change that
// rise that way), so the block keeps snow on its uphill side and what that
// leaves steeper than repose the grid's passes take down within the block.
// A limited slope (minmod) instead would stand the 2 x 2 apex blocks of a pile
// flat and leave the pile flatter than repose (an 8 x 8 tower: apex 4 % lower,
// diagonal flanks 1.4 degrees below). The four offsets cancel, so the block's
// volume is its coarse cell's; they are scaled down where a cell would go
// negative, and a block losing more than a cell holds (a pile's edge whose
// mean moved) gives in proportion to what each cell holds. The last rounding
// residue goes to the block's deepest cell (the first in row order among
// equals), so each block holds its volume to rounding and the field's mass is
// the coarse level's, which the passes keep to rounding. Each block is computed
// alone in a fixed order, so the result does not depend on the thread count.
#pragma once

#include "terrain/grid.h"

namespace drift::snow {

struct CoarseLevel {
  terrain::Grid<float> ground;  // mean ground + the snow that may not move
  terrain::Grid<double> snow;   // the snow that may move (see above)
};

// The coarse level of (ground, snow): floor(width / 2) x floor(height / 2) cells.
CoarseLevel restrict_to_coarse(const terrain::Grid<float>& ground,
                               const terrain::Grid<double>& snow);

// Hands the coarse level's change of snow (from `before`, as restricted, to
// `after`, settled on `coarse_ground`) down to the fine snow, block by block
// (see above).
void prolong_change(const terrain::Grid<float>& coarse_ground, const terrain::Grid<double>& before,
                    const terrain::Grid<double>& after, terrain::Grid<double>& snow);

}  // namespace drift::snow
