// The coarse-to-fine start of snow stabilisation (snow/stabilise_grid.h): the
// field is settled first on grids of 2 x 2 blocks, coarsest first, and each
// level's change of snow is handed down to the next finer level as its start
// (nested iteration, as in full multigrid). The passes' slow mode is a
// diffusion (a slope at repose shifting in parallel takes O(L^2) passes for L
// cells), so a level of cells twice as large settles it in a quarter of the
// passes, each on a quarter of the cells; the finer level then has mostly its
// own detail left. Every level ends by the passes' own convergence criterion,
// the finest included, so whatever the start no pair is left steeper than
// repose. But the passes only ever flatten: where a coarse level left a pile
// flatter than the grid's own passes would (its apex and toe, which 2 x 2
// blocks cannot draw), the finer level keeps it so. An 8 x 8 tower ends with
// its apex 4 % lower and its diagonal flanks 1.4 degrees below repose, which
// is why the start is an option (StabiliseOptions::coarse_levels), not the
// default; docs/snowfall.md has the figures.
//
// Restriction (a coarse cell is four fine cells; the caller doubles the cell
// size, so the repose drop per direction follows it):
//  - the coarse surface is the block's mean surface (ground + snow);
//  - only the layer that every cell of the block holds (the block's least
//    depth) is the coarse cell's snow, free to move; the rest of the block's
//    snow counts as coarse ground. Snow in a partly bare block (snow caught in
//    a hollow, the edge of a drift) stays where the fine passes left it, as a
//    fine cell next to bare ground gives only what it holds. With the whole
//    block's mean as mobile snow, snow the fine ground would hold in hollows
//    smaller than a coarse cell was carried off (at 1024^2 with four levels,
//    54 % of the ground covered against 63 %);
//  - a grid of odd width or height leaves its last column or row out of the
//    coarse level, which is closed there like any edge; the finer level's
//    passes settle that strip.
// Prolongation: each block's layer changes by its coarse cell's change d,
// linearly across the block: d plus slopes towards the neighbouring blocks'
// changes (minmod-limited, so no new extremes), scaled down where a cell would
// lose more than it holds. The four offsets cancel, so the block's volume is
// its coarse cell's; a piecewise-constant change (each block even) leaves
// steps between blocks that the fine passes must creep away (at 1024^2 with
// one level: 2,477 fine passes against 2,416, RMS 2.7 cm from the passes alone
// against 2.3 cm). The last rounding residue goes to the block's deepest cell
// (the first in row order among equals), so each block holds its volume to
// rounding and the field's mass is the coarse level's, which the passes keep
// to rounding. Each block is computed alone in a fixed order, so the result
// does not depend on the thread count.
#pragma once

#include "terrain/grid.h"

namespace drift::snow {

struct CoarseLevel {
  terrain::Grid<float> ground;  // mean ground + the snow that may not move
  terrain::Grid<double> snow;   // the layer every fine cell of the block holds
};

// The coarse level of (ground, snow): floor(width / 2) x floor(height / 2) cells.
CoarseLevel restrict_to_coarse(const terrain::Grid<float>& ground,
                               const terrain::Grid<double>& snow);

// Hands the coarse level's change of snow (from `before`, as restricted, to
// `after`, settled) down to the fine snow, block by block (see above).
void prolong_change(const terrain::Grid<double>& before, const terrain::Grid<double>& after,
                    terrain::Grid<double>& snow);

}  // namespace drift::snow
