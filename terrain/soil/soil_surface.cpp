#include "terrain/soil/soil_surface.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "terrain/products.h"
#include "terrain/soil/height_spans.h"

namespace drift::soil {

namespace {

// Reshapes one column's piles (see surface.h). Only piles that hold soil: a
// bare pile (ground, a body's top) would get a ramp of density at its top
// and so a phantom sheet of soil over every body and terrain voxel. The one
// exception is a pile's foot: bare floor beside soil on the floor keeps its
// ramp (`foot`), which with the pad row under the floor lets the surface run
// down into the ground at the pile's edge instead of ending in a step.
void straighten_column(const HeightSpan* spans, int count, int nz, int ramp, bool foot,
                       const float* rho, float* out) {
  for (int s = 0; s < count; ++s) {
    const HeightSpan& p = spans[s];
    if (p.type != SpanType::Piled) continue;
    if (!holds_soil(p) && !(foot && s == 0 && p.bottom == 0.0f)) continue;
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

// Height (voxels) of the soil a column's floor pile holds; 0 for bare
// ground (or a trace), -1 where the column stands on a body (no floor pile).
float floor_pile_top(const float* rho, const float* psi, int nz) {
  HeightSpan spans[HeightSpans::kMaxSpans];
  const int n = build_column_spans(rho, psi, nz, spans, HeightSpans::kMaxSpans);
  if (n == 0 || psi[0] > 0 || spans[0].type != SpanType::Piled) return -1.0f;
  if (spans[0].bottom != 0.0f) return -1.0f;
  return holds_soil(spans[0]) ? std::max(0.0f, spans[0].top) : 0.0f;
}

// floor_pile_top of every column (y * nx + x).
std::vector<float> floor_pile_tops(const SoilState& s) {
  const terrain::Grid3Shape& g = s.shape;
  std::vector<float> top(g.columns());
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x) {
      const std::size_t c = g.column(x, y);
      top[static_cast<std::size_t>(y) * g.nx + x] =
          floor_pile_top(s.rho.data() + c, s.psi.data() + c, g.nz);
    }
  });
  return top;
}

// True if a column beside (x, y) holds soil on the floor (`top` > 0).
bool beside_floor_soil(const std::vector<float>& top, const terrain::Grid3Shape& g, int x, int y) {
  for (int ny = std::max(0, y - 1); ny <= std::min(g.ny - 1, y + 1); ++ny)
    for (int nx = std::max(0, x - 1); nx <= std::min(g.nx - 1, x + 1); ++nx)
      if (top[static_cast<std::size_t>(ny) * g.nx + nx] > 0) return true;
  return false;
}

}  // namespace

std::vector<float> surface_density(const SoilState& s, const SurfaceOptions& o) {
  std::vector<float> out = s.rho;
  if (o.ridges == RidgeFix::Off) return out;
  const terrain::Grid3Shape& g = s.shape;
  const int ramp = std::clamp(o.ramp_voxels, 1, 16);
  const std::vector<float> top = floor_pile_tops(s);
  tbb::parallel_for(0, g.ny, [&](int y) {
    HeightSpan spans[HeightSpans::kMaxSpans];
    for (int x = 0; x < g.nx; ++x) {
      const std::size_t c = g.column(x, y);
      const int n = build_column_spans(s.rho.data() + c, s.psi.data() + c, g.nz, spans,
                                       HeightSpans::kMaxSpans);
      const bool foot =
          top[static_cast<std::size_t>(y) * g.nx + x] == 0.0f && beside_floor_soil(top, g, x, y);
      straighten_column(spans, n, g.nz, ramp, foot, s.rho.data() + c, out.data() + c);
    }
  });
  return out;
}

namespace {

// The pad row under the floor: the ramp of surface.h carried on half a voxel
// below the floor, for columns holding soil on the floor and for the bare
// columns beside them (as if their top lay a quarter voxel under the floor,
// so the soil's surface runs on down into the ground instead of ending in a
// rim); 0 elsewhere.
std::vector<float> floor_pads(const SoilState& s, int ramp) {
  const terrain::Grid3Shape& g = s.shape;
  const std::vector<float> top = floor_pile_tops(s);
  auto ramp_at = [ramp](float t) {
    return std::clamp(0.5f + (t + 0.5f) / (2.0f * ramp), 0.f, 1.f);
  };
  std::vector<float> pad(g.columns(), 0.0f);
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x) {
      const float t = top[static_cast<std::size_t>(y) * g.nx + x];
      float& out = pad[static_cast<std::size_t>(y) * g.nx + x];
      if (t > 0) out = ramp_at(t);
      if (t == 0 && beside_floor_soil(top, g, x, y)) out = ramp_at(-0.25f);
    }
  });
  return pad;
}

// The straightened density over a grid one voxel deeper, the pad row under
// the floor, so a pile's foot thinner than half a voxel (whose first voxel
// centre lies above its top) still has its 0.5 crossing at its top instead of
// ending in a half-voxel step at the floor.
terrain::Mesh floor_padded_surface(const SoilState& s, const std::vector<float>& field, int ramp) {
  const terrain::Grid3Shape& g = s.shape;
  terrain::Grid3Shape padded = g;
  padded.nz = g.nz + 1;
  padded.origin.z() -= g.voxel_size;
  const std::vector<float> pad = floor_pads(s, ramp);
  std::vector<float> out(padded.count());
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x) {
      const std::size_t c = g.column(x, y), pc = padded.column(x, y);
      out[pc] = pad[static_cast<std::size_t>(y) * g.nx + x];
      std::copy(field.begin() + c, field.begin() + c + g.nz, out.begin() + pc + 1);
    }
  });
  terrain::Mesh mesh = iso_surface(padded, out);
  // What lies under the floor is hidden by the ground: flatten it just under
  // the floor (a hundredth of a voxel, so the ground, not a sheet of soil
  // level with it, is what a ray sees there). The surface stays closed and
  // encloses the soil's volume.
  const float floor = static_cast<float>(g.origin.z() - 0.01 * g.voxel_size);
  for (auto& p : mesh.positions) p.z() = std::max(p.z(), floor);
  return mesh;
}

}  // namespace

float moisture_at(const SoilState& s, const Eigen::Vector3f& p) {
  const terrain::Grid3Shape& g = s.shape;
  // Voxel coordinates with voxel centres at whole numbers.
  const double gx = (p.x() - g.origin.x()) / g.voxel_size - 0.5;
  const double gy = (p.y() - g.origin.y()) / g.voxel_size - 0.5;
  const double gz = (p.z() - g.origin.z()) / g.voxel_size - 0.5;
  const int x0 = static_cast<int>(std::floor(gx)), y0 = static_cast<int>(std::floor(gy)),
            z0 = static_cast<int>(std::floor(gz));
  // Trilinear weights times the soil each voxel holds: the surface lies
  // where rho crosses 0.5, so half its corner voxels are (nearly) empty and
  // must not dilute the moisture; a second ring covers a vertex whose corners
  // hold no soil at all (the ridge fix and the floor pad move the surface).
  for (int ring = 0; ring <= 1; ++ring) {
    double w = 0, wm = 0;
    for (int z = z0 - ring; z <= z0 + 1 + ring; ++z)
      for (int y = y0 - ring; y <= y0 + 1 + ring; ++y)
        for (int x = x0 - ring; x <= x0 + 1 + ring; ++x) {
          if (!g.contains(x, y, z)) continue;
          const std::size_t i = g.index(x, y, z);
          if (s.rho[i] <= 0) continue;
          const double t = std::max(0.0, 1 - std::abs(gx - x) / (1 + ring)) *
                           std::max(0.0, 1 - std::abs(gy - y) / (1 + ring)) *
                           std::max(0.0, 1 - std::abs(gz - z) / (1 + ring)) * s.rho[i];
          w += t;
          wm += t * s.wet[i];
        }
    if (w > 0) return static_cast<float>(wm / w);
  }
  return 0.0f;
}

terrain::Mesh soil_surface(const SoilState& s, const SurfaceOptions& o) {
  terrain::Mesh mesh =
      o.ridges == RidgeFix::Off
          ? iso_surface(s.shape, surface_density(s, o))
          : floor_padded_surface(s, surface_density(s, o), std::clamp(o.ramp_voxels, 1, 16));
  std::vector<float> wetness(mesh.positions.size());
  tbb::parallel_for(std::size_t{0}, wetness.size(),
                    [&](std::size_t v) { wetness[v] = moisture_at(s, mesh.positions[v]); });
  mesh.vertex_attributes.push_back({terrain::products::kWetness, std::move(wetness)});
  return mesh;
}

}  // namespace drift::soil
