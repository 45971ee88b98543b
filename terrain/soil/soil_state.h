// The state of the voxel soil (paper 004, sec. 3.1): per voxel the soil
// density rho in [0, 1] (fraction of a full voxel), its velocity u (m/s), the
// direction f of the force a rigid body applies to it, and the rigid-body
// density psi (the collision field), with 0 <= rho + psi <= 1 (eq. 17).
//
// Structure of arrays on one Grid3Shape (z fastest, see terrain/grid3.h):
// every pass streams only the fields it needs.
#pragma once

#include <cstdint>
#include <vector>

#include "terrain/grid3.h"

namespace drift::soil {

struct SoilState {
  terrain::Grid3Shape shape;
  std::vector<float> rho;         // soil density, fraction of a voxel
  std::vector<float> ux, uy, uz;  // velocity, m/s
  std::vector<float> fx, fy, fz;  // applied-force direction (non-zero only where collided)
  std::vector<float> psi;         // rigid-body density (collision field), this step
  std::vector<float> psi_static;  // the part of psi from static bodies and terrain

  // Back buffers the passes write before swapping, and per-voxel scratch.
  struct Back {
    std::vector<float> rho, ux, uy, uz, fx, fy, fz, moving;
    std::vector<std::uint8_t> visited;  // the settle's walks: voxels seen (cleared after each)
    std::vector<std::size_t> walk;      // and their queue
  } back;

  // Allocates every field, zeroed. Checks the size against the memory
  // available first (drift::Error naming the grid and the fix).
  explicit SoilState(const terrain::Grid3Shape& shape);
  SoilState() = default;

  std::size_t size() const { return rho.size(); }
  // Swaps the back buffers of rho, u and f in.
  void swap_back();
  // Total soil, in voxels (sum of rho), summed in double in a fixed order.
  double mass() const;
};

// Copies voxel i's rho, u and f from the back buffers to the front.
void copy_back(SoilState& state, std::size_t i);

// Bytes SoilState plus the step's scratch buffers take for `shape`.
std::uint64_t soil_state_bytes(const terrain::Grid3Shape& shape);

}  // namespace drift::soil
