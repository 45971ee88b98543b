// Marks block by block (issue 36 item 3): `drift marks --block N` on a ground
// raster larger than memory. The ground is read and written a block at a time
// through GDAL (terrain/raster_blocks.h); only the blocks an object comes
// near are simulated, each on a window of the block and a halo, and the rest
// are copied as they are.
//
// The halo. Marks are local: an object changes the cells under it, the ring
// its displaced material is spread over (at most `margin` cells beyond the
// footprint, plus mud's heave band) and the slopes that erosion relaxes from
// there, and a relaxation pass reads at most two cells away (a taker's share
// reads its givers' excesses, which read their neighbours). A window is the
// block grown by `halo` cells on every side (default 64: 64 cm at 1 cm cells,
// twice the widest rim the galleries show), then grown again to hold whole
// every object's footprint that comes into it (a footprint cut by a window
// would press only part of the object). The run then checks its own
// assumption: if any cell within a band of 2 + margin cells of the window's
// edge (where that edge is not the raster's) changed, marks may have reached
// beyond the window, and the block is worked again with the halo doubled,
// up to the whole raster. Objects farther than the halo from a block are
// taken not to reach it.
//
// Equality with one pass: a window places its objects in the raster's cell
// coordinates less a whole number of cells (exact), draws the erosion's
// roughness per raster cell, stands objects that follow the ground on the
// raster's heights and starts at a multiple of 4 cells (the coarse levels'
// grid, multires.h), so where the check holds, a block's cells are the
// one-pass run's bit for bit (tests/marks/marks_blocks_test.cpp).
#pragma once

#include <filesystem>
#include <vector>

#include "terrain/marks/marks.h"

namespace drift::marks {

struct MarksBlockFiles {
  std::filesystem::path ground, output, disturbed;  // disturbed: optional
  int block = 0;  // cells a side (0: DRIFT_BLOCK_CELLS, else 1024; rounded up to a multiple of 4)
  int halo = 64;  // cells (rounded up to a multiple of 4)
  // The ground's materials per region, read per window as the ground is (at
  // most one of the two; the rasters must be the ground's size):
  std::filesystem::path materials;   // per cell 0 sand, 1 mud, 2 snow (drift marks --materials)
  std::filesystem::path snow_depth;  // snow (`snow`) where deeper than snow_min, else `material`
  double snow_min = 0.01;            // m
  Material snow = *material_preset("snow");
};

struct MarksBlockReport {
  MarksReport report;  // steps; per object its steps, contact and clearance
  int block = 0, halo = 0;
  int blocks = 0, simulated = 0;  // blocks in all, blocks an object came near
  int widened = 0;                // times a window was worked again with a doubled halo
  int largest_halo = 0;           // cells, the widest halo a block needed
};

// Marks `objects` make in the ground of files.ground (`material` for every
// cell, or per region from files.materials or files.snow_depth; objects' own
// materials still apply where they walk), written to files.output. The
// report's volumes and contact steps count each object's step once, from a
// window that holds its footprint whole, added in the one-pass run's order.
// Throws drift::Error as simulate_marks does.
MarksBlockReport marks_to_files(const MarksBlockFiles& files,
                                const std::vector<MarkObject>& objects, const Material& material,
                                const MarksOptions& options,
                                const ProgressFn& progress = no_progress);

}  // namespace drift::marks
