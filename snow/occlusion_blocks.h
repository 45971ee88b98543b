// The ground's snow probability (horizon-sweep occlusion, snow/occlusion_horizon.h)
// block by block, each block swept with a halo around it, giving the same bits
// as one pass over the whole raster (issue 36, item 3).
//
// The halo: a sweep line l carries S = max(h, lerp(S of line l - 1) - drop),
// drop = the height the ray loses over one line (line spacing x tan(elevation)).
// Terrain n lines upstream can raise S at a cell by at most relief - n x drop,
// relief = the raster's highest minus its lowest ground, so beyond n = relief /
// drop lines it can never win over the cell's own height: the occlusion horizon
// reaches relief / tan(elevation) metres. A cell's S depends on the two cells
// bracketing its ray on the line before, whose brackets drift from the ray by
// up to one element a line, so over n lines the cells it depends on lie within
// n x (|shift| + 1) <= 2 n elements across the sweep (|shift| <= 1: the sweep
// runs along the axis nearer the direction). A block swept with a halo of 2 n
// + 2 cells on every side therefore gives its cells exactly the S of one pass
// (by induction: the block's S is at most the whole raster's, which is at most
// the larger of the block's and relief - k x drop after k lines; in floats
// too, as every step is monotone), and the same probability, bit for bit.
// Ground only: objects (OSMesa depth maps) are not tiled here.
#pragma once

#include <vector>

#include "snow/snowfall_directions.h"
#include "snow/snowfall_probability.h"
#include "snow/snowfall_scene.h"

namespace drift::snow {

// The halo (cells) the horizon sweep of these directions needs on `scene`.
int occlusion_halo_cells(const SnowScene& scene, const std::vector<FallDirection>& dirs);

// snow_probability's ground and ground_facing, computed on blocks of `block`
// cells a side (each with occlusion_halo_cells around it); faces are empty.
// Throws drift::Error for a scene with objects or the OpenGL occlusion.
SnowProbability ground_probability_in_blocks(const SnowScene& scene,
                                             const std::vector<FallDirection>& dirs, int block,
                                             const ProbabilityOptions& options = {});

}  // namespace drift::snow
