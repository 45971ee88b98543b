// A soil scenario as data: the grid, the soil, the bodies of soil at the
// start, the rigid bodies and the terrain they rest on. The command line
// reads it from a TOML file (pipeline/soil_scenario_file.cpp); tests build it
// in code. make_simulation() checks it and voxelises it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "terrain/grid.h"
#include "terrain/soil/simulation.h"

namespace drift::soil {

// Terrain the soil rests on, voxelised into the static collision field.
struct TerrainSource {
  enum class Kind { None, HeightField, Voxel } kind = Kind::None;
  // HeightField: heights in metres over the grid's columns (x east, row 0
  // north, as terrain::Grid), cell = voxel; voxels below it are solid,
  // the voxel it cuts is partly (eq. 17's psi as the covered fraction).
  terrain::HeightField heights;
  // Voxel: a 3-D terrain with overhangs from a density function (thesis
  // sec. 2.2.2, fig. 52): ground at `base` metres, a ridge with an overhanging
  // ledge, low hills from seeded noise.
  double base = 0.0;
  unsigned long long seed = 1;
};

struct SoilBody {
  std::string name;
  std::vector<Primitive> primitives;
  Eigen::Vector3d position{0, 0, 0};
  // With a height-field terrain: position.z is above the ground under
  // (position.x, position.y) rather than above the grid's origin.
  bool on_ground = false;
  // Its moisture in [0, 1] (thesis 5.3.4); unset: the soil's `moisture`.
  std::optional<double> moisture;
};

struct SoilScenario {
  std::string name;
  terrain::Grid3Shape shape{64, 64, 64, 0.1, {0, 0, 0}};
  terrain::GeoReference geo;  // of the top-surface raster; empty CRS = local
  SoilOptions options;
  int steps = 600;  // [0, kMaxSteps]
  static constexpr int kMaxSteps = 10000000;
  std::vector<SoilBody> soil;
  std::vector<RigidObject> bodies;
  TerrainSource terrain;
};

// Checks sizes, memory, bodies and options (drift::Error naming what is
// wrong), allocates and voxelises: terrain and static bodies into
// psi_static, soil bodies into rho (only where there is room).
SoilSimulation make_simulation(const SoilScenario& scenario);

// The voxel terrain's density at p (metres): > 0 inside rock. Exposed for tests.
double voxel_terrain_density(const Eigen::Vector3d& p, const terrain::Grid3Shape& shape,
                             double base, unsigned long long seed);

}  // namespace drift::soil
