#include "terrain/soil/scenario.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "terrain/bilinear.h"
#include "terrain/error.h"
#include "terrain/hash.h"
#include "terrain/memory.h"

namespace drift::soil {

namespace {

// Counter-based value noise on a lattice (terrain/hash.h), so the terrain
// does not depend on evaluation order.
double lattice(long i, long j, unsigned long long seed) {
  using terrain::mix64;
  return terrain::unit_double(
      mix64(mix64(mix64(seed) ^ static_cast<std::uint64_t>(i)) ^ static_cast<std::uint64_t>(j)));
}

double value_noise(double x, double y, unsigned long long seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const long i = static_cast<long>(fx), j = static_cast<long>(fy);
  double tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);  // smoothstep: no creases at lattice lines
  ty = ty * ty * (3 - 2 * ty);
  return terrain::bilinear_blend(lattice(i, j, seed), lattice(i + 1, j, seed),
                                 lattice(i, j + 1, seed), lattice(i + 1, j + 1, seed), tx, ty);
}

void voxelise_heights(const terrain::HeightField& heights, SoilState& s) {
  const terrain::Grid3Shape& g = s.shape;
  if (heights.width() != g.nx || heights.height() != g.ny)
    throw Error("terrain raster is " + std::to_string(heights.width()) + " x " +
                std::to_string(heights.height()) + " cells but the soil grid has " +
                std::to_string(g.nx) + " x " + std::to_string(g.ny) + " columns");
  for (float v : heights.values())
    if (!std::isfinite(v))
      throw Error("terrain raster has a non-finite height (nodata?); fill it first");
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x) {
      const double top = (heights(x, g.ny - 1 - y) - g.origin.z()) / g.voxel_size;
      for (int z = 0; z < g.nz; ++z)
        s.psi_static[g.index(x, y, z)] = static_cast<float>(std::clamp(top - z, 0.0, 1.0));
    }
  });
}

void voxelise_density(const SoilScenario& sc, SoilState& s) {
  const terrain::Grid3Shape& g = s.shape;
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x)
      for (int z = 0; z < g.nz; ++z) {
        // 2 x 2 x 2 samples of the density's sign: partial coverage at the rock's surface.
        int in = 0;
        for (int k = 0; k < 8; ++k) {
          const Eigen::Vector3d p =
              g.origin + g.voxel_size * Eigen::Vector3d(x + 0.25 + 0.5 * (k & 1),
                                                        y + 0.25 + 0.5 * ((k >> 1) & 1),
                                                        z + 0.25 + 0.5 * ((k >> 2) & 1));
          in += voxel_terrain_density(p, g, sc.terrain.base, sc.terrain.seed) > 0;
        }
        s.psi_static[g.index(x, y, z)] = in / 8.0f;
      }
  });
}

}  // namespace

double voxel_terrain_density(const Eigen::Vector3d& p, const terrain::Grid3Shape& g, double base,
                             unsigned long long seed) {
  const double w = g.nx * g.voxel_size, d = g.ny * g.voxel_size, hgt = g.nz * g.voxel_size;
  const double u = (p.x() - g.origin.x()) / w, v = (p.y() - g.origin.y()) / d;
  const double z = p.z() - g.origin.z();
  // Ground with low seeded hills.
  double ground = base + 0.06 * hgt * (value_noise(4 * u, 4 * v, seed) - 0.5) +
                  0.03 * hgt * (value_noise(9 * u, 9 * v, seed + 1) - 0.5);
  double rock = ground - z;
  // A ridge along y in the east third, rising to 60 % of the grid's height ...
  const double ridge_top = base + 0.6 * hgt * std::exp(-std::pow((u - 0.75) / 0.12, 2));
  rock = std::max(rock, ridge_top - z);
  // ... with a ledge jutting west from its flank, hollow below (an overhang).
  const double ledge_z = base + 0.35 * hgt, ledge_t = 0.05 * hgt;
  const double ledge = std::min({ledge_t - std::abs(z - ledge_z), (u - 0.45) * w, (0.8 - u) * w,
                                 (0.25 - std::abs(v - 0.5)) * d});
  return std::max(rock, ledge);
}

SoilSimulation make_simulation(const SoilScenario& sc) {
  const auto& g = sc.shape;
  if (!(std::isfinite(g.voxel_size) && g.voxel_size > 0))
    throw Error("scenario '" + sc.name + "': voxel size " + std::to_string(g.voxel_size) +
                " must be a positive number of metres");
  if (!g.origin.allFinite()) throw Error("scenario '" + sc.name + "': grid origin is not finite");
  if (sc.steps < 0) throw Error("scenario '" + sc.name + "': steps must be >= 0");
  sc.options.validate();
  require_memory(soil_run_bytes(g),  // the whole run's, before any of it is allocated
                 "soil grid " + std::to_string(g.nx) + " x " + std::to_string(g.ny) + " x " +
                     std::to_string(g.nz),
                 "use a smaller grid or larger voxels");
  SoilState state(g);  // checks sizes and memory
  if (sc.terrain.kind == TerrainSource::Kind::HeightField)
    voxelise_heights(sc.terrain.heights, state);
  if (sc.terrain.kind == TerrainSource::Kind::Voxel) voxelise_density(sc, state);
  for (const RigidObject& b : sc.bodies) {
    validate(b, "body");
    if (!b.moves()) add_coverage(placed(b, 0.0), g, state.psi_static);
  }
  // Moving bodies at time 0 take their room before the soil is poured in.
  state.psi = state.psi_static;
  for (const RigidObject& b : sc.bodies)
    if (b.moves()) add_coverage(placed(b, 0.0), g, state.psi);
  for (const SoilBody& s : sc.soil) {
    RigidObject probe;
    probe.name = s.name;
    probe.primitives = s.primitives;
    validate(probe, "soil body");
    Eigen::Vector3d at = s.position;
    if (s.on_ground && sc.terrain.kind == TerrainSource::Kind::HeightField) {
      const auto& hf = sc.terrain.heights;
      const double col = (at.x() - g.origin.x()) / g.voxel_size - 0.5;
      const double row = hf.height() - (at.y() - g.origin.y()) / g.voxel_size - 0.5;
      at.z() += terrain::bilinear_clamped(hf, col, row);
    }
    const double m = s.moisture.value_or(sc.options.soil.moisture);
    if (!(m >= 0 && m <= 1))
      throw Error("scenario '" + sc.name + "': soil body '" + s.name + "' moisture " +
                  std::to_string(m) + " must lie in [0, 1] (0 dry .. 1 damp)");
    add_soil(state, s.primitives, at, m);
  }
  std::vector<RigidObject> moving;
  for (const RigidObject& b : sc.bodies)
    if (b.moves()) moving.push_back(b);
  return SoilSimulation(std::move(state), std::move(moving), sc.options);
}

}  // namespace drift::soil
