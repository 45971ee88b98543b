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
#include "snow/snowfall_probability.h"
#include "snow/snowfall_scene.h"
#include "terrain/grid.h"
#include "terrain/mesh.h"
#include "terrain/progress.h"

namespace drift::snow {

struct SnowfallOptions {
  double azimuth_deg = 0.0;
  double elevation_deg = 90.0;
  double spread_deg = 5.0;
  int maps = 16;
  double rate_m_per_h = 0.02;
  double hours = 10.0;
  double repose_deg = 40.0;
  std::uint64_t seed = 1;
  double mesh_max_edge = 0.25;
  ProbabilityOptions occlusion;
  CoverageOptions coverage;
  double tolerance = 1e-6;  // m: object stabilisation stops when nothing moves more per pass
  // m: on the ground a pair steeper than repose by less than this, or a film
  // thinner, is stable (stabilise_grid.h)
  double ground_tolerance = 1e-3;
  int max_iterations = 100000;
  // The coarse-to-fine start of the ground's stabilisation (stabilise_grid.h
  // StabiliseOptions::coarse_levels); 0: the passes on the grid alone.
  int coarse_levels = 0;

  // Throws drift::Error naming the parameter, its value and the valid range.
  void validate() const;
};

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
