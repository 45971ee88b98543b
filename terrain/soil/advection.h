// Projectile motion of the voxel soil (paper 004, sec. 3.2.1-3.2.2):
// advection with locked voxels and backflow (eqs. 23-28), overflow
// resolution (fig. 30) and gravity (eq. 29).
#pragma once

#include "terrain/soil/soil_state.h"
#include "terrain/soil/transport.h"

namespace drift::soil {

// Fig. 30's heuristics for the soil an advection leaves in overflowed voxels.
enum class OverflowHeuristic {
  Spread,  // evenly into the 26 neighbours (suits falling soil)
  Up,      // up one voxel (suits piles; the thesis's choice)
  UpNine,  // into the nine voxels one level up, weights 1/4 centre, 1/8 edge, 1/16 corner
};

// Moves rho, u and f by u dt (at most one voxel per axis, eqs. 23-28): a
// voxel with rho + psi >= 1 is locked and takes no inflow but its own;
// whatever would enter it (or leave the grid) returns to its source with zero
// velocity. u and f are averaged weighted by the inflowing density. Returns
// per column the z-range that gathered (the only voxels whose rho changed).
detail::Ranges advect(SoilState& state, double dt);

// Per column (y * nx + x), non-zero where something may have overflowed.
using ColumnMask = std::vector<std::uint8_t>;

// `passes` Jacobi passes of the heuristic: the excess rho - (1 - psi) of each
// overflowed voxel moves to the heuristic's neighbours that are inside the
// grid and not solid rigid body (psi < 1); "up" keeps the excess of a voxel
// under a solid one (soil never passes through a body). With `dirty`, "up"
// passes visit only the columns it marks (the spreading heuristics visit
// every column).
void resolve_overflow(SoilState& state, OverflowHeuristic heuristic, int passes,
                      const ColumnMask* dirty = nullptr);

// Guarantees eq. 17 after resolve_overflow without moving soil through a
// body (docs/soil.md, Method 4): soil inside a solid body voxel goes to the nearer face of
// the body in its column; per run of open voxels of a column, bottom to top,
// any excess is carried up to the next voxel with room and from the run's
// top back down; what a run cannot hold (soil pressed under a body) goes
// sideways, breadth-first through open voxels to the nearest room. Beyond the
// thesis, which accepted leftover overflow; mass is unchanged. With `dirty`,
// only the columns it marks.
void settle_overflow(SoilState& state, const ColumnMask* dirty = nullptr);

// Eq. 29: u += g dt where rho > 0, u = 0 (and f = 0) where there is no soil.
void apply_gravity(SoilState& state, double gravity, double dt);

}  // namespace drift::soil
