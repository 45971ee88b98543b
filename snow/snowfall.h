// Snowfall with occlusion, irregular motion and stabilisation (paper 003:
// Moriki & Tokoi, "Real-time simulation of the fallen snow with consideration to
// the irregular motion of the snow"; docs/snowfall.md records the decisions
// the paper leaves open).
//
// Stages: depth maps along jittered directions -> probability per ground cell
// and object face (snowfall_probability.h) -> amount = probability x rate x
// hours -> stabilisation on each object (polygon variant, stabilise_mesh.h), snow
// shed by the objects dropped on the ground below -> stabilisation on the ground
// (texel variant, stabilise_grid.h) -> coverage with thin-snow speckle and
// sparse adhesion (adhesion_coverage.h).
//
// Parameters (interface units; ranges checked by validate()):
// | name           | meaning                                        | unit | default | range      |
// | azimuth        | where the snow comes from, clockwise from N    | deg  | 0       | [0, 360]   |
// | elevation      | above the horizon; 90 = falling straight down  | deg  | 90      | (0, 90]    |
// | spread         | std. deviation of the jitter (wind gusts)      | deg  | 5       | [0, 30]    |
// | maps           | jittered depth maps                            |      | 16      | [1, 1024]  |
// | rate           | fresh snow depth on open flat ground per hour  | m/h  | 0.02    | (0, 10]    |
// | hours          | duration                                       | h    | 10      | (0, 1e4]   |
// | repose         | angle of repose of snow                        | deg  | 40      | (0, 90)    |
// | mesh_max_edge  | object edges are split to at most this         | m    | 0.25    | 0 or > 0   |
//
// Modelled: occlusion by ground and objects (either side of any face), partial
// occlusion of cells by sub-cell objects, snow sliding within the ground and
// within each object, snow shed by objects falling straight down onto the ground.
// Not modelled: snow from one object landing on another, snow on the ground
// flowing into the space inside an object's footprint (a hut's floor), wind
// transport (drifts), compaction, melting.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "snow/adhesion_coverage.h"
#include "snow/snowfall_options.h"
#include "snow/snowfall_probability.h"
#include "snow/snowfall_scene.h"
#include "terrain/grid.h"
#include "terrain/mesh.h"
#include "terrain/progress.h"

namespace drift::snow {

struct SnowfallResult {
  terrain::HeightField depth;     // m of snow (vertical), georeference of the ground
  terrain::HeightField coverage;  // [0, 1]
  // All objects in one mesh, vertices raised by their snow, in the declared
  // form terrain::products::kSnowyObjects: per-vertex snow depth (m),
  // probability, coverage, adhesion and the index of the object in the input
  // list. Positions are relative to mesh_origin (CRS metres): place it there.
  terrain::Mesh objects;
  Eigen::Vector3d mesh_origin{0, 0, 0};
  // Bookkeeping (m^3): fallen = on ground + on objects + lost off the raster's edge.
  double fallen_volume = 0, ground_volume = 0, object_volume = 0, shed_volume = 0, lost_volume = 0;
  int ground_iterations = 0, object_iterations = 0;
  bool converged = true;
};

SnowfallResult simulate_snowfall(const terrain::HeightField& ground,
                                 const std::vector<terrain::PlacedMesh>& objects,
                                 const SnowfallOptions& options,
                                 const ProgressFn& progress = no_progress);

}  // namespace drift::snow
