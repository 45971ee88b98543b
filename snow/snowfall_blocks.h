// Snowfall on the ground block by block (issue 36, item 3): `drift snow fall
// --block N --stabilise direct` on a ground raster larger than memory. The
// ground is read and the depth, cover and surface written a block at a time
// through GDAL (terrain/raster_blocks.h); each block's snow is settled on a
// window of the block and a halo, and its probability swept on that window
// and the occlusion's own halo (snow/occlusion_blocks.h).
//
// The halo of the stabilisation. Snow slides as far as the ground lets it (an
// avalanche down a long slope crosses many blocks), so no halo is right a
// priori; as marks' blocks do (terrain/marks/marks_blocks.h), the run checks
// its own assumption and works a block again with the halo doubled, up to
// the whole raster, where it fails. The one-step solver (stabilise_direct.h)
// reads and writes a cell's 8 neighbours at a time, and a window differs from
// the whole raster only in its outermost ring of cells (their outer
// neighbours are missing); so the window's snow is the whole raster's
// wherever no snow was cut, routed or heaped (settle_at_rest's `touched`)
// within a band of kBand cells of the window's edge (where that edge is not
// the raster's), neither in the block's own run (snow of the block reaching
// out) nor, checked once every block is done, in the result of the blocks
// whose cells that band holds (snow from outside reaching in). Checked in
// both directions, a block's snow stays inside its window in the whole run,
// and snow from beyond never enters it. Every operation inside runs in the
// whole run's order (row-major cell order and height order are kept by a
// window), so the block's cells are the whole raster's bit for bit
// (tests/snow/snowfall_blocks_test.cpp, with blocks of 16 to 40 cells and a
// slope whose snow runs over several blocks).
//
// Memory: one window at a time (its ground with the occlusion's halo, its
// probability, snow and the solver's workspace) and one bit a cell of the
// whole raster (where snow moved, for the check from outside).
#pragma once

#include <filesystem>

#include "snow/snowfall_options.h"
#include "terrain/progress.h"

namespace drift::snow {

struct SnowfallBlockFiles {
  std::filesystem::path ground, depth, cover, surface;  // cover, surface: optional
  int block = 0;                                        // cells a side (> 0)
  int halo = 64;  // cells: the stabilisation's first halo (doubled where needed)
};

struct SnowfallBlockReport {
  int width = 0, height = 0, block = 0;
  int blocks = 0;
  int occlusion_halo = 0;   // cells
  int widened = 0;          // times a window was worked again with a doubled halo
  int windows_widened = 0;  // windows worked again wider at least once (of blocks)
  int largest_halo = 0;     // cells, the widest stabilisation halo a block needed
  double fallen_volume = 0, ground_volume = 0;  // m^3 (sums block by block)
  bool converged = true;  // no pair steeper than repose by more than the tolerance
};

// Snow on the ground of files.ground (no objects; the horizon sweep; the
// one-step stabilisation with options.direct_layers), written block by block
// to files.depth (and cover, surface). The rasters are simulate_snowfall's
// with direct_stabilise, bit for bit. Throws drift::Error for what
// simulate_snowfall refuses.
SnowfallBlockReport snowfall_to_files(const SnowfallBlockFiles& files,
                                      const SnowfallOptions& options,
                                      const ProgressFn& progress = no_progress);

}  // namespace drift::snow
