// The multi-level heightfield (paper 004, sec. 3.2.3, tables 1-3, eq. 30):
// per column of the voxel grid, the sorted, non-overlapping height spans of
// rigid body, piled soil and falling soil. Heights are in voxels above the
// bottom of the grid (z up; the thesis counts j downwards, eq. 30's
// M - 1 - j + omega is our z + omega).
//
// Construction, bottom to top (the thesis's rules):
// - rigid body: a run of voxels with psi = 1, widened by the partial body in
//   the voxel below (body at its top) and in the voxel above (body at its
//   bottom); it needs at least one solid voxel.
// - piled soil: starts at the floor of the grid and directly on every rigid
//   span; runs through voxels full of soil (rho + psi = 1) and ends in the
//   first that is not, at height z + psi (if the body lies at its bottom) + rho.
//   A pile can have zero height: bare ground and bare tops of bodies can
//   receive sliding soil.
// - falling soil: a run of voxels full of soil with no body, not on a pile.
// Partly filled voxels that are not the top of a pile belong to no span:
// that soil is falling, and advection moves it.
#pragma once

#include <cstdint>
#include <vector>

#include "terrain/grid3.h"

namespace drift::soil {

enum class SpanType : std::uint8_t { Rigid, Piled, Falling };

struct HeightSpan {
  float bottom = 0, top = 0;    // B, T in voxels
  float soil = 0;               // soil it holds (sum of rho over its voxels)
  std::int16_t top_voxel = -1;  // z of the voxel holding the top (piles)
  SpanType type = SpanType::Piled;
};

struct HeightSpans {
  static constexpr int kMaxSpans = 16;  // per column; spans above are not kept
  terrain::Grid3Shape shape;
  std::vector<HeightSpan> spans;    // columns x kMaxSpans
  std::vector<std::uint8_t> count;  // spans per column

  const HeightSpan* column(std::size_t c) const { return spans.data() + c * kMaxSpans; }
};

// Builds the spans of one column from its rho and psi (nz values each).
int build_column_spans(const float* rho, const float* psi, int nz, HeightSpan* out, int max_spans);

// All columns, in parallel.
void build_height_spans(const terrain::Grid3Shape& shape, const std::vector<float>& rho,
                        const std::vector<float>& psi, HeightSpans& out);

}  // namespace drift::soil
