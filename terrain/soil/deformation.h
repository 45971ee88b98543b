// Contact motion (paper 004, sec. 3.2.4): soil that a moving rigid body
// collides with is pushed through the grid along the body's motion.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "terrain/soil/primitives.h"
#include "terrain/soil/soil_state.h"
#include "terrain/soil/transport.h"

namespace drift::soil {

// A moving body's voxel box and motion this step: the velocity (m/s) of its
// pivot, its angular velocity (rad/s) about it; a point p moves at
// velocity + spin x (p - pivot).
struct BodyMotion {
  VoxelBox box;
  Eigen::Vector3d velocity{0, 0, 0};
  Eigen::Vector3d spin{0, 0, 0};
  Eigen::Vector3d pivot{0, 0, 0};
};

// Force application, eq. 33: in a collided voxel (rho + psi > 1) holding
// rigid body, f = the body's direction of motion at the voxel (the first of `bodies`
// whose box holds the voxel; straight up for a body at rest, which can only
// lift what it overlaps); a collided voxel with no body keeps f; elsewhere f = 0.
void apply_forces(SoilState& state, const std::vector<BodyMotion>& bodies);

// One force-propagation iteration, eqs. 34-35: the collided soil
// rho + psi - 1 of every voxel moves by f scaled to a largest component of 1
// (so it leaves its voxel entirely) into neighbours that are in the grid and
// not solid body (psi < 1), with u; anything refused comes back. f becomes
// the inflow-weighted mean of the arriving forces where the voxel is still
// collided, 0 elsewhere. Returns per column the z-range that changed.
// `scan`: if given, only its voxels can be pushed (the last iteration's
// returned ranges: outside them nothing changed, so nothing is pushed and
// the moving soil is already 0); the first iteration of a step scans all.
detail::Ranges propagate_forces(SoilState& state, const detail::Ranges* scan = nullptr);

}  // namespace drift::soil

namespace drift::soil {

// Soil resting on a moving body rides with it (issue 33, item 4): the soil
// standing on a body's top in a column (the contiguous soil above the top
// voxel the body holds, not the static ground) moves sideways by the
// body's surface velocity at the contact, v + omega x (p - pivot), over dt
// (at most a voxel), spread bilinearly over the four columns it lands
// between at the same height (mass and water kept). The thesis's model
// only pushes collided soil, so a turning platform slid out from under its
// load. Serial, in a fixed order (the same bits on any thread count).
// Columns that may now overflow are flagged in `touched` (settle them).
void carry_riding_soil(SoilState& state, const std::vector<BodyMotion>& bodies, double dt,
                       std::vector<std::uint8_t>& touched);

}  // namespace drift::soil
