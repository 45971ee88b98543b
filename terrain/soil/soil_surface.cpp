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

// Column (x, y) of surface_density into `out` (nz values), given every
// column's floor_pile_top: reads the column itself and its neighbours' tops.
void density_column(const SoilState& s, const std::vector<float>& top, int ramp, int x, int y,
                    float* out) {
  const terrain::Grid3Shape& g = s.shape;
  const std::size_t c = g.column(x, y);
  std::copy(s.rho.begin() + c, s.rho.begin() + c + g.nz, out);
  HeightSpan spans[HeightSpans::kMaxSpans];
  const int n =
      build_column_spans(s.rho.data() + c, s.psi.data() + c, g.nz, spans, HeightSpans::kMaxSpans);
  const bool foot =
      top[static_cast<std::size_t>(y) * g.nx + x] == 0.0f && beside_floor_soil(top, g, x, y);
  straighten_column(spans, n, g.nz, ramp, foot, s.rho.data() + c, out);
}

// The pad row under the floor: the ramp of surface.h carried on half a voxel
// below the floor, for columns holding soil on the floor and for the bare
// columns beside them (as if their top lay a quarter voxel under the floor,
// so the soil's surface runs on down into the ground instead of ending in a
// rim); 0 elsewhere.
float floor_pad(const std::vector<float>& top, const terrain::Grid3Shape& g, int ramp, int x,
                int y) {
  auto ramp_at = [ramp](float t) {
    return std::clamp(0.5f + (t + 0.5f) / (2.0f * ramp), 0.f, 1.f);
  };
  const float t = top[static_cast<std::size_t>(y) * g.nx + x];
  if (t > 0) return ramp_at(t);
  if (t == 0 && beside_floor_soil(top, g, x, y)) return ramp_at(-0.25f);
  return 0.0f;
}

// The grid the surface is extracted from: with the ridge fix, one voxel
// deeper (the pad row under the floor), so a pile's foot thinner than half a
// voxel (whose first voxel centre lies above its top) still has its 0.5
// crossing at its top instead of ending in a half-voxel step at the floor.
terrain::Grid3Shape field_shape(const terrain::Grid3Shape& g, bool padded) {
  terrain::Grid3Shape f = g;
  if (padded) {
    f.nz = g.nz + 1;
    f.origin.z() -= g.voxel_size;
  }
  return f;
}

// Column (x, y) of the surface's field (field_shape's column, nz or nz + 1
// values).
void field_column(const SoilState& s, const std::vector<float>& top, const SurfaceOptions& o, int x,
                  int y, float* out) {
  const terrain::Grid3Shape& g = s.shape;
  if (o.ridges == RidgeFix::Off) {
    std::copy_n(s.rho.begin() + g.column(x, y), g.nz, out);
    return;
  }
  const int ramp = std::clamp(o.ramp_voxels, 1, 16);
  out[0] = floor_pad(top, g, ramp, x, y);
  density_column(s, top, ramp, x, y, out + 1);
}

// The mesh of `mesher`, with what lies under the floor flattened and the
// per-vertex wetness.
terrain::Mesh finish_mesh(const SoilState& s, const SurfaceOptions& o, terrain::Mesh mesh) {
  if (o.ridges != RidgeFix::Off) {
    // What lies under the floor is hidden by the ground: flatten it just
    // under the floor (a hundredth of a voxel, so the ground, not a sheet of
    // soil level with it, is what a ray sees there). The surface stays
    // closed and encloses the soil's volume.
    const float floor = static_cast<float>(s.shape.origin.z() - 0.01 * s.shape.voxel_size);
    for (auto& p : mesh.positions) p.z() = std::max(p.z(), floor);
  }
  std::vector<float> wetness(mesh.positions.size());
  tbb::parallel_for(std::size_t{0}, wetness.size(),
                    [&](std::size_t v) { wetness[v] = moisture_at(s, mesh.positions[v]); });
  mesh.vertex_attributes.push_back({terrain::products::kWetness, std::move(wetness)});
  return mesh;
}

}  // namespace

std::vector<float> surface_density(const SoilState& s, const SurfaceOptions& o) {
  if (o.ridges == RidgeFix::Off) return s.rho;
  const terrain::Grid3Shape& g = s.shape;
  std::vector<float> out(g.count());
  const int ramp = std::clamp(o.ramp_voxels, 1, 16);
  const std::vector<float> top = floor_pile_tops(s);
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x) density_column(s, top, ramp, x, y, out.data() + g.column(x, y));
  });
  return out;
}

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
  // The axes' weights are computed once per corner row (not per corner:
  // 1.9 ms of a 64^3 frame went here), in the same expression and product
  // order as before, so the wetness keeps its bits.
  for (int ring = 0; ring <= 1; ++ring) {
    const int n = 2 + 2 * ring;
    double wx[4], wy[4], wz[4];
    for (int k = 0; k < n; ++k) {
      wx[k] = std::max(0.0, 1 - std::abs(gx - (x0 - ring + k)) / (1 + ring));
      wy[k] = std::max(0.0, 1 - std::abs(gy - (y0 - ring + k)) / (1 + ring));
      wz[k] = std::max(0.0, 1 - std::abs(gz - (z0 - ring + k)) / (1 + ring));
    }
    double w = 0, wm = 0;
    for (int kz = 0; kz < n; ++kz) {
      const int z = z0 - ring + kz;
      if (z < 0 || z >= g.nz) continue;
      for (int ky = 0; ky < n; ++ky) {
        const int y = y0 - ring + ky;
        if (y < 0 || y >= g.ny) continue;
        for (int kx = 0; kx < n; ++kx) {
          const int x = x0 - ring + kx;
          if (x < 0 || x >= g.nx) continue;
          const std::size_t i = g.index(x, y, z);
          if (s.rho[i] <= 0) continue;
          const double t = wx[kx] * wy[ky] * wz[kz] * s.rho[i];
          w += t;
          wm += t * s.wet[i];
        }
      }
    }
    if (w > 0) return static_cast<float>(wm / w);
  }
  return 0.0f;
}

terrain::Mesh soil_surface(const SoilState& s, const SurfaceOptions& o) {
  const terrain::Grid3Shape f = field_shape(s.shape, o.ridges != RidgeFix::Off);
  const std::vector<float> top =
      o.ridges == RidgeFix::Off ? std::vector<float>{} : floor_pile_tops(s);
  std::vector<float> field(f.count());
  tbb::parallel_for(0, f.ny, [&](int y) {
    for (int x = 0; x < f.nx; ++x) field_column(s, top, o, x, y, field.data() + f.column(x, y));
  });
  return finish_mesh(s, o, iso_surface(f, field));
}

struct SurfaceExtractor::Impl {
  SurfaceOptions options;
  bool primed = false;
  terrain::Grid3Shape shape;          // the state's
  std::vector<float> rho, psi;        // as the last extract() saw them
  std::vector<float> top;             // floor_pile_tops of rho, psi
  std::vector<float> field;           // the surface's field (field_shape)
  std::vector<unsigned char> column;  // per column: 1 = rho or psi changed, 2 = recompute
  IsoMesher mesher;
  Work work;
};

SurfaceExtractor::SurfaceExtractor(const SurfaceOptions& o) : impl_(std::make_unique<Impl>()) {
  impl_->options = o;
}
SurfaceExtractor::~SurfaceExtractor() = default;
SurfaceExtractor::SurfaceExtractor(SurfaceExtractor&&) noexcept = default;
SurfaceExtractor& SurfaceExtractor::operator=(SurfaceExtractor&&) noexcept = default;
SurfaceExtractor::Work SurfaceExtractor::last_work() const { return impl_->work; }

terrain::Mesh SurfaceExtractor::extract(const SoilState& s) {
  Impl& m = *impl_;
  const SurfaceOptions& o = m.options;
  const terrain::Grid3Shape& g = s.shape;
  const bool ridges = o.ridges != RidgeFix::Off;
  const terrain::Grid3Shape f = field_shape(g, ridges);
  const bool same = m.primed && g.nx == m.shape.nx && g.ny == m.shape.ny && g.nz == m.shape.nz &&
                    g.voxel_size == m.shape.voxel_size && g.origin == m.shape.origin;
  if (!same) {
    // First frame: everything.
    m.primed = true;
    m.shape = g;
    m.rho = s.rho;
    m.psi = s.psi;
    if (ridges) m.top = floor_pile_tops(s);
    m.field.assign(f.count(), 0.0f);
    tbb::parallel_for(0, f.ny, [&](int y) {
      for (int x = 0; x < f.nx; ++x)
        field_column(s, m.top, o, x, y, m.field.data() + f.column(x, y));
    });
    m.work = {g.columns(), m.mesher.update(f, m.field, nullptr)};
    return finish_mesh(s, o, m.mesher.mesh());
  }
  // Columns whose rho or psi changed: their own floor-pile top again.
  const std::size_t nz = static_cast<std::size_t>(g.nz);
  m.column.assign(g.columns(), 0);
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x) {
      const std::size_t c = g.column(x, y), k = static_cast<std::size_t>(y) * g.nx + x;
      if (std::equal(s.rho.begin() + c, s.rho.begin() + c + nz, m.rho.begin() + c) &&
          std::equal(s.psi.begin() + c, s.psi.begin() + c + nz, m.psi.begin() + c))
        continue;
      std::copy_n(s.rho.begin() + c, nz, m.rho.begin() + c);
      std::copy_n(s.psi.begin() + c, nz, m.psi.begin() + c);
      if (ridges) m.top[k] = floor_pile_top(s.rho.data() + c, s.psi.data() + c, g.nz);
      m.column[k] = 1;
    }
  });
  // A column's field reads its neighbours' tops (a pile's foot, the floor
  // pad): recompute the changed columns and those beside them.
  const int reach = ridges ? 1 : 0;
  std::vector<int> recompute;
  for (int y = 0; y < g.ny; ++y)
    for (int x = 0; x < g.nx; ++x) {
      bool near = false;
      for (int v = std::max(0, y - reach); v <= std::min(g.ny - 1, y + reach) && !near; ++v)
        for (int u = std::max(0, x - reach); u <= std::min(g.nx - 1, x + reach) && !near; ++u)
          near = m.column[static_cast<std::size_t>(v) * g.nx + u] == 1;
      if (near) recompute.push_back(y * g.nx + x);
    }
  // Each recomputed column's field; the z range (lo, hi) that changed.
  std::vector<std::pair<int, int>> changed(recompute.size(), {f.nz, -1});
  tbb::parallel_for(std::size_t{0}, recompute.size(), [&](std::size_t i) {
    const int x = recompute[i] % g.nx, y = recompute[i] / g.nx;
    float column[4097];
    field_column(s, m.top, o, x, y, column);
    float* kept = m.field.data() + f.column(x, y);
    for (int z = 0; z < f.nz; ++z)
      if (column[z] != kept[z] || std::signbit(column[z]) != std::signbit(kept[z])) {
        changed[i].first = std::min(changed[i].first, z);
        changed[i].second = z;
        kept[z] = column[z];
      }
  });
  // Flag the leaf of every changed value: IsoMesher rebuilds the blocks
  // that read it.
  constexpr int L = IsoMesher::kLeaf;
  const int bx = (f.nx + L - 1) / L, by = (f.ny + L - 1) / L, bz = (f.nz + L - 1) / L;
  std::vector<unsigned char> dirty(static_cast<std::size_t>(bx) * by * bz, 0);
  for (std::size_t i = 0; i < recompute.size(); ++i) {
    if (changed[i].second < 0) continue;
    const int x = recompute[i] % g.nx, y = recompute[i] / g.nx;
    for (int w = changed[i].first / L; w <= changed[i].second / L; ++w)
      dirty[(static_cast<std::size_t>(w) * by + y / L) * bx + x / L] = 1;
  }
  m.work = {recompute.size(), m.mesher.update(f, m.field, &dirty)};
  return finish_mesh(s, o, m.mesher.mesh());
}

}  // namespace drift::soil
