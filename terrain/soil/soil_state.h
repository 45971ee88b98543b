// The state of the voxel soil (paper 004, sec. 3.1): per voxel the soil
// density rho in [0, 1] (fraction of a full voxel), its velocity u (m/s), the
// direction f of the force a rigid body applies to it, the rigid-body
// density psi (the collision field), with 0 <= rho + psi <= 1 (eq. 17), and
// the soil's moisture m in [0, 1] (thesis 5.3.4: a per-voxel field the
// renderer shows as wetness). Moisture is a property of the soil, carried
// with it: every pass that moves an amount of soil moves m with it and
// mixes it weighted by the amounts, so the water, sum of rho m, is conserved
// as the soil is (issue 33, item 2).
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
  std::vector<float> wet;         // moisture of the soil in the voxel, 0 dry .. 1 damp

  // Back buffers the passes write before swapping, and per-voxel scratch.
  struct Back {
    std::vector<float> rho, ux, uy, uz, fx, fy, fz, wet, moving;
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
  // Total water, sum of rho m (voxels of soil times moisture), in double in a fixed order.
  double water() const;
};

// Copies voxel i's rho, u, f and moisture from the back buffers to the front.
void copy_back(SoilState& state, std::size_t i);

// Moisture after `in` of soil with moisture `m_in` joins `rho` of soil with
// moisture `m`: the mass-weighted mean.
inline float mix_moisture(float rho, float m, float in, float m_in) {
  const float total = rho + in;
  return total > 1e-30f ? (rho * m + in * m_in) / total : m_in;
}

// Bytes SoilState plus the step's scratch buffers take for `shape`.
std::uint64_t soil_state_bytes(const terrain::Grid3Shape& shape);

}  // namespace drift::soil
