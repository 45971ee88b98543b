// The probability that snow reaches each ground cell and each object face
// (paper 003, 2.1(1)-(2), 2.2(2), 2.3(2)): for every jittered direction, a point
// is lit when nothing nearer the source covers it in that direction's depth map;
// the probability is the weighted fraction of directions in which it is lit.
//
// Occluders: the ground (by the horizon sweep, or by an OSMesa depth map of its
// triangles) and the objects (OSMesa depth maps around each object, holding every
// object that overlaps them, at a texel fine enough for the object). Ground cells
// whose centre can fall in an object's shadow are sampled K x K times within the
// cell, so objects smaller than a cell shade it partially.
#pragma once

#include <vector>

#include "snow/snowfall_directions.h"
#include "snow/snowfall_scene.h"
#include "terrain/progress.h"

namespace drift::snow {

enum class TerrainOcclusion {
  Sweep,   // per-line horizon sweep (occlusion_horizon.h): fast, exact at cell centres
  OpenGL,  // OSMesa depth map of the height field's triangles (texel = cell)
};

struct ProbabilityOptions {
  TerrainOcclusion terrain = TerrainOcclusion::Sweep;
  double object_texel = 0.0;  // m; 0 = largest object extent / 1024, at most half a cell
  int ground_samples = 0;     // K for cells near objects, [1, 16]; 0 = auto (cell / 2 texels)
};

struct SnowProbability {
  terrain::Grid<float> ground;             // [0, 1] per cell
  std::vector<std::vector<float>> faces;   // per object, per triangle: [0, 1]
  std::vector<std::vector<float>> facing;  // per object, per triangle: sum w lit (n . d)
  terrain::Grid<float> ground_facing;      // per cell: sum w lit (n . d)
};

SnowProbability snow_probability(const SnowScene& scene, const std::vector<FallDirection>& dirs,
                                 const ProbabilityOptions& options = {},
                                 const ProgressFn& progress = no_progress);

}  // namespace drift::snow
