// Small soil scenes and measurements shared by the soil tests.
#pragma once

#include <cstdint>
#include <vector>

#include "terrain/soil/simulation.h"

namespace drift::soil::fixtures {

// A vertical cylinder of soil of `radius` and `height` voxels standing in the
// middle of an n x n x nz grid of 1-voxel = `voxel` metres.
SoilSimulation column_scene(int n, int nz, double radius, double height, double voxel,
                            const SoilOptions& options);

// Runs until no voxel changes by more than `tolerance` over `window` steps,
// or `max_steps`; returns the steps taken.
int run_until_settled(SoilSimulation& sim, int max_steps, int window = 20, float tolerance = 1e-4f);

// The column tops of a pile (voxels) and their top-weighted centroid, in
// voxel units with column x's centre at x + 0.5 (the one convention of the
// measures below).
struct PileTops {
  int nx = 0, ny = 0;
  std::vector<float> top;  // nx * ny, row y at y * nx
  float peak = 0;
  double cx = 0, cy = 0;
  float operator()(int x, int y) const { return top[static_cast<std::size_t>(y) * nx + x]; }
  // Bilinear between the column centres at (x, y) in voxel units.
  double at(double x, double y) const;
};
PileTops pile_tops(const SoilState& state);

// Radius (voxels) at which the pile's top falls below `fraction` of its peak,
// walking out from the centroid along `directions` directions: max / min - 1.
double radius_spread(const SoilState& state, double fraction, int directions);

// Slope angle (degrees) of a settled pile's flank: least-squares fit of the
// column tops against the distance from the pile's axis, over columns whose
// top lies between 20 % and 80 % of the highest. Also reports the fit's
// direction-wise spread in `spread_deg` (max - min of 8 sector fits).
double pile_angle_deg(const SoilState& state, double* spread_deg = nullptr);

// FNV-1a over the bits of rho, u, f.
std::uint64_t state_hash(const SoilState& state);

// Largest rho + psi and smallest rho over the grid.
float max_fill(const SoilState& state);
float min_rho(const SoilState& state);

}  // namespace drift::soil::fixtures

#include "terrain/soil/scenario.h"

namespace drift::soil::fixtures {

// The thesis's benchmark scene (sec. 4.2): an n^3 grid of 0.1 m voxels, a
// layer of soil 0.25 n deep, a block 0.1 n x 0.6 n x 0.3 n ploughing through
// it along +x at 1.5 m/s from x = 0.1 n to 0.7 n, its bottom 0.17 n above
// the floor.
SoilScenario push_scenario(int n, const SoilOptions& options = {});

// A column of soil dropped onto a block (fig. 48) in an n x n x n grid.
SoilScenario pour_block_scenario(int n, const SoilOptions& options = {});

}  // namespace drift::soil::fixtures

namespace drift::soil::fixtures {
// Top of column (x, y) in voxels (terrain/soil/top_surface.h).
float column_top_of(const SoilState& state, int x, int y);
}  // namespace drift::soil::fixtures
