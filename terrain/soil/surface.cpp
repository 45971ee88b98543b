#include "terrain/soil/surface.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "terrain/soil/height_spans.h"

namespace drift::soil {

namespace {

// Reshapes one column's piles (see surface.h).
void straighten_column(const HeightSpan* spans, int count, int nz, int ramp, const float* rho,
                       float* out) {
  for (int s = 0; s < count; ++s) {
    const HeightSpan& p = spans[s];
    if (p.type != SpanType::Piled) continue;
    const int floor = std::max(0, static_cast<int>(std::floor(p.bottom)));
    int ceiling = nz;  // first voxel of the next span
    if (s + 1 < count) ceiling = std::min(nz, static_cast<int>(std::floor(spans[s + 1].bottom)));
    const int lo = std::max(floor, static_cast<int>(std::floor(p.top - ramp)));
    const int hi = std::min(ceiling - 1, static_cast<int>(std::ceil(p.top + ramp)));
    for (int z = lo; z <= hi; ++z) {
      const float d = std::clamp(0.5f + (p.top - (z + 0.5f)) / (2.0f * ramp), 0.0f, 1.0f);
      out[z] = z > p.top_voxel ? std::max(d, rho[z]) : d;
    }
  }
}

}  // namespace

std::vector<float> surface_density(const SoilState& s, const SurfaceOptions& o) {
  std::vector<float> out = s.rho;
  if (o.ridges == RidgeFix::Off) return out;
  const terrain::Grid3Shape& g = s.shape;
  const int ramp = std::clamp(o.ramp_voxels, 1, 16);
  tbb::parallel_for(0, g.ny, [&](int y) {
    HeightSpan spans[HeightSpans::kMaxSpans];
    for (int x = 0; x < g.nx; ++x) {
      const std::size_t c = g.column(x, y);
      const int n = build_column_spans(s.rho.data() + c, s.psi.data() + c, g.nz, spans,
                                       HeightSpans::kMaxSpans);
      straighten_column(spans, n, g.nz, ramp, s.rho.data() + c, out.data() + c);
    }
  });
  return out;
}

namespace {

// The ramp's value half a voxel below the floor under a pile on the floor
// that holds soil, else 0 (bare ground and columns standing on a body).
float floor_pad(const float* rho, const float* psi, int nz, int ramp) {
  HeightSpan spans[HeightSpans::kMaxSpans];
  const int n = build_column_spans(rho, psi, nz, spans, HeightSpans::kMaxSpans);
  if (n == 0 || psi[0] > 0) return 0.0f;
  const HeightSpan& p = spans[0];
  if (p.type != SpanType::Piled || p.bottom != 0.0f || !(p.top > 0.0f)) return 0.0f;
  return std::clamp(0.5f + (p.top + 0.5f) / (2.0f * ramp), 0.0f, 1.0f);
}

// The straightened density over a grid one voxel deeper: a row under the
// floor carries the ramp on down, so a pile's foot thinner than half a voxel
// (whose first voxel centre lies above its top) still has its 0.5 crossing
// at its top instead of ending in a half-voxel step at the floor.
terrain::Mesh floor_padded_surface(const SoilState& s, const std::vector<float>& field, int ramp) {
  const terrain::Grid3Shape& g = s.shape;
  terrain::Grid3Shape padded = g;
  padded.nz = g.nz + 1;
  padded.origin.z() -= g.voxel_size;
  std::vector<float> out(padded.count());
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x) {
      const std::size_t c = g.column(x, y), pc = padded.column(x, y);
      out[pc] = floor_pad(s.rho.data() + c, s.psi.data() + c, g.nz, ramp);
      std::copy(field.begin() + c, field.begin() + c + g.nz, out.begin() + pc + 1);
    }
  });
  terrain::Mesh mesh = iso_surface(padded, out);
  // What lies under the floor is hidden by the ground: flatten it onto the
  // floor, so the surface stays closed and encloses the soil's volume.
  const float floor = static_cast<float>(g.origin.z());
  for (auto& p : mesh.positions) p.z() = std::max(p.z(), floor);
  return mesh;
}

}  // namespace

terrain::Mesh soil_surface(const SoilState& s, const SurfaceOptions& o, double moisture) {
  terrain::Mesh mesh =
      o.ridges == RidgeFix::Off
          ? iso_surface(s.shape, surface_density(s, o))
          : floor_padded_surface(s, surface_density(s, o), std::clamp(o.ramp_voxels, 1, 16));
  mesh.vertex_attributes.push_back(
      {"wetness", std::vector<float>(mesh.positions.size(), static_cast<float>(moisture))});
  return mesh;
}

}  // namespace drift::soil
