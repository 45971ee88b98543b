#include "terrain/soil/height_spans.h"

#include <tbb/parallel_for.h>

namespace drift::soil {

namespace {
constexpr float kFull = 1.0f - 1e-5f;

struct ColumnScan {
  const float *rho, *psi;
  int nz;
  HeightSpan* out;
  int max_spans, n = 0;

  bool solid(int z) const { return psi[z] >= kFull; }
  void push(SpanType t, float b, float top, float soil, int top_voxel) {
    if (n < max_spans) out[n++] = {b, top, soil, static_cast<std::int16_t>(top_voxel), t};
  }

  // A pile from height `b` starting in voxel z; returns the voxel after it.
  int pile(int z, float b) {
    float soil = 0;
    int j = z;
    while (j < nz && !solid(j) && rho[j] + psi[j] >= kFull) soil += rho[j++];
    if (j == nz) {
      push(SpanType::Piled, b, static_cast<float>(nz), soil, nz - 1);
      return nz;
    }
    if (solid(j)) {  // runs into a body right above: top z + rho (table 2), the body's bottom
      const float capped =
          j > z && psi[j - 1] > 0 ? static_cast<float>(j) - psi[j - 1] : static_cast<float>(j);
      push(SpanType::Piled, b, capped, soil, j - 1);
      return j;
    }
    const bool body_above = j + 1 < nz && solid(j + 1);
    const float base = body_above ? 0.0f : psi[j];  // body at the bottom of the top voxel
    push(SpanType::Piled, b, static_cast<float>(j) + base + rho[j], soil + rho[j], j);
    return j + 1;
  }

  // A body from voxel z (solid); returns the voxel after its solid run.
  int rigid(int z) {
    const float b = z > 0 && psi[z - 1] > 0 && !solid(z - 1) ? static_cast<float>(z) - psi[z - 1]
                                                             : static_cast<float>(z);
    int j = z;
    while (j < nz && solid(j)) ++j;
    const float top = j < nz ? static_cast<float>(j) + psi[j] : static_cast<float>(nz);
    push(SpanType::Rigid, b, top, 0.0f, j - 1);
    return j;
  }

  void run() {
    int z = solid(0) ? rigid(0) : pile(0, 0.0f);
    if (solid(0) && z < nz) z = pile(z, out[n - 1].top);
    while (z < nz && n < max_spans) {
      if (solid(z)) {
        z = rigid(z);
        if (z < nz) z = pile(z, out[n - 1].top);
      } else if (rho[z] >= kFull && psi[z] <= 0) {
        int j = z;
        float soil = 0;
        while (j < nz && rho[j] >= kFull && psi[j] <= 0) soil += rho[j++];
        push(SpanType::Falling, static_cast<float>(z), static_cast<float>(j), soil, j - 1);
        z = j;
      } else {
        ++z;
      }
    }
  }
};

}  // namespace

int build_column_spans(const float* rho, const float* psi, int nz, HeightSpan* out, int max_spans) {
  ColumnScan scan{rho, psi, nz, out, max_spans};
  scan.run();
  return scan.n;
}

void build_height_spans(const terrain::Grid3Shape& shape, const std::vector<float>& rho,
                        const std::vector<float>& psi, HeightSpans& out) {
  out.shape = shape;
  out.spans.resize(shape.columns() * HeightSpans::kMaxSpans);
  out.count.resize(shape.columns());
  tbb::parallel_for(0, shape.ny, [&](int y) {
    for (int x = 0; x < shape.nx; ++x) {
      const std::size_t c = static_cast<std::size_t>(y) * shape.nx + x;
      out.count[c] = static_cast<std::uint8_t>(build_column_spans(
          rho.data() + c * shape.nz, psi.data() + c * shape.nz, shape.nz,
          out.spans.data() + c * HeightSpans::kMaxSpans, HeightSpans::kMaxSpans));
    }
  });
}

}  // namespace drift::soil
