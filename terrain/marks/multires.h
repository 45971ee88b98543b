// Marks worked on a coarser copy of the ground (paper 000, 3.6): for objects
// far from the camera (A) or simple objects in loose ground (B) the collision,
// displacement and erosion run on a half or quarter resolution copy of the
// object's window (block means, so volume is kept), and the change is written
// back onto the full-resolution field by linear interpolation over the changed
// area only. The changed fine cells are returned so that the caller remembers
// them and the next steps' erosion smooths them at full resolution.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "terrain/grid.h"
#include "terrain/marks/ground_material.h"
#include "terrain/marks/object_bottom.h"

namespace drift::marks {

struct CoarseResult {
  double collided = 0.0, displaced = 0.0, compressed = 0.0;  // m of coarse height, summed
  int contact_cells = 0;                                     // coarse cells
  std::vector<int> changed;  // fine flat indices whose height changed
  BottomMap bottom;          // the coarse bottom over the fine cells (nearest)
};

// tris: in the fine grid's cell space. level: 2 or 4. dx, dy: fine cell sizes (m).
// seed: the erosion's roughness draws (terrain/slope_relax.h).
CoarseResult deform_coarse(terrain::Grid<double>& heights, const MaterialField& materials,
                           const CellTriangles& tris, int level, double dx, double dy, int margin,
                           int erosion_passes, BottomRasteriser& rasteriser,
                           const std::optional<Eigen::Vector2d>& drag,
                           terrain::Grid<float>* disturbed, std::uint64_t seed = 0);

}  // namespace drift::marks
