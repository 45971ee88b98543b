// Water in the soil (issue 33, item 3; the thesis's 5.3.4 leaves moisture
// fixed): moisture drains down through the soil and evaporates from its
// exposed top, so a wetted heap dries from the top over time.
//
// The moisture m in [0, 1] of a voxel is read as its relative saturation S
// (water content over the porosity theta_s). Water in a voxel, w = rho m, is
// in voxels of saturated soil: w = 1 holds h^3 theta_s of water (h the voxel
// edge).
// - Drainage: gravity drainage under a unit hydraulic gradient, Darcy's flux
//   q = K(S) = K_s S^(2b + 3) (Campbell 1974, Soil Sci. 117; b and theta_s of
//   Clapp & Hornberger 1978), from each soil voxel into the soil voxel under
//   it: dw = q dt / (h theta_s), at most what the voxel holds and the room
//   (rho - w) below. The steep power makes damp soil drain fast and nearly
//   dry soil hold its water (field capacity). Water leaves no pile: the
//   lowest voxel of a pile keeps what reaches it, so water is conserved
//   where it only moves (SoilDrainage.WaterOnlyMovesDownWithoutEvaporation).
// - Evaporation at rate E (m/s of water) from the top soil voxel of each
//   pile with air above: dw = E dt / (h theta_s), at most what it holds.
// Fluxes come from the state before the pass (Jacobi): every column is
// written by one task only, so the result is the same bits on any thread
// count.
#pragma once

#include "terrain/soil/soil_state.h"
#include "terrain/soil/soil_type.h"

namespace drift::soil {

// One time step dt (s) of drainage and evaporation; returns nothing: the
// water evaporated is sum(rho m) before minus after.
void drain_moisture(SoilState& state, const SoilType& soil, double dt);

}  // namespace drift::soil
