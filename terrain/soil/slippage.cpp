#include "terrain/soil/slippage.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "terrain/soil/soil_slice.h"

namespace drift::soil {

namespace {

// Neighbour offsets, paired so that d ^ 1 is the opposite direction.
constexpr int kDx[8] = {1, -1, 0, 0, 1, -1, 1, -1};
constexpr int kDy[8] = {0, 0, 1, -1, 1, -1, -1, 1};

std::size_t slot(std::size_t column, int pile, int dir) {
  return (column * Slippage::kMaxPiles + pile) * Slippage::kDirections + dir;
}

// The lower pile of column n that pile p slides onto: the highest pile below
// p's top that meets it (eq. 31, >= 0). -1 if none.
int lower_pile(const HeightSpan& p, const HeightSpan* n, int count) {
  int best = -1;
  for (int q = 0; q < count; ++q) {
    if (n[q].type != SpanType::Piled || n[q].top >= p.top) continue;
    if (std::min(p.top, n[q].top) - std::max(p.bottom, n[q].bottom) >= 0) best = q;
  }
  return best;
}

bool holds_height(const HeightSpan* n, int count, float h) {
  for (int q = 0; q < count; ++q)
    if (n[q].bottom <= h && h <= n[q].top) return true;
  return false;
}

// Bottom of the first span of column n above height h (the ceiling of eq. 32).
float ceiling_above(const HeightSpan* n, int count, float h, float grid_top) {
  for (int q = 0; q < count; ++q)
    if (n[q].bottom > h) return n[q].bottom;
  return grid_top;
}

// Removes `amount` of soil from voxel `top` downwards (not below `floor`).
void remove_down(float* rho, int top, int floor, float amount) {
  for (int z = top; z >= floor && amount > 0; --z) {
    const float take = std::min(rho[z], amount);
    rho[z] -= take;
    amount -= take;
  }
}

// Adds `amount` of soil from voxel `from` upwards into the room left by soil
// and body; what finds no room stays in the top voxel (mass is kept).
void add_up(float* rho, const float* psi, int from, int nz, float amount) {
  for (int z = std::max(0, from); z < nz && amount > 0; ++z) {
    const float put = std::min(amount, std::max(0.0f, 1.0f - psi[z] - rho[z]));
    rho[z] += put;
    amount -= put;
  }
  if (amount > 0) rho[nz - 1] += amount;
}

}  // namespace

Slippage::Slippage(const terrain::Grid3Shape& shape)
    : shape_(shape),
      out_(shape.columns() * kMaxPiles * kDirections),
      speed_(shape.columns() * kMaxPiles * kDirections, 0.0f) {}

void Slippage::step(SoilState& state, const SoilType& soil, double gravity, double dt) {
  build_height_spans(shape_, state.rho, state.psi, spans_);
  compute_slices(soil, gravity, dt);
  apply(state);
}

void Slippage::compute_slices(const SoilType& soil, double gravity, double dt) {
  const SliceConstants k{shape_.voxel_size,
                         soil.phi_deg * M_PI / 180.0,
                         soil.effective_cohesion(),
                         soil.gamma,
                         gravity,
                         dt,
                         static_cast<float>(shape_.nz)};
  tbb::parallel_for(0, shape_.ny, [&](int y) {
    for (int x = 0; x < shape_.nx; ++x) {
      const std::size_t col = static_cast<std::size_t>(y) * shape_.nx + x;
      const HeightSpan* spans = spans_.column(col);
      const int count = spans_.count[col];
      int pile = 0;
      for (int s = 0; s < count && pile < kMaxPiles; ++s) {
        if (spans[s].type != SpanType::Piled) continue;
        slide_pile(x, y, pile, spans[s], k);
        ++pile;
      }
      for (; pile < kMaxPiles; ++pile)
        for (int d = 0; d < kDirections; ++d) {
          out_[slot(col, pile, d)] = Out{};
          speed_[slot(col, pile, d)] = 0;
        }
    }
  });
}

void Slippage::slide_pile(int x, int y, int pile, const HeightSpan& p, const SliceConstants& k) {
  const std::size_t col = static_cast<std::size_t>(y) * shape_.nx + x;
  double total = 0;
  for (int d = 0; d < kDirections; ++d) {
    Out& o = out_[slot(col, pile, d)];
    float& v = speed_[slot(col, pile, d)];
    o = Out{};
    const int nx = x + kDx[d], ny = y + kDy[d];
    if (nx < 0 || ny < 0 || nx >= shape_.nx || ny >= shape_.ny) {
      v = 0;
      continue;
    }
    const std::size_t ncol = static_cast<std::size_t>(ny) * shape_.nx + nx;
    slide_slice(p, spans_.column(ncol), spans_.count[ncol], d, k, o, v);
    total += o.dh;
  }
  // A pile cannot give more soil than it holds.
  if (total > p.soil && total > 0) {
    const float scale = static_cast<float>(p.soil / total * (1.0 - 1e-6));
    for (int d = 0; d < kDirections; ++d) out_[slot(col, pile, d)].dh *= scale;
  }
}

void Slippage::slide_slice(const HeightSpan& p, const HeightSpan* n, int ncount, int d,
                           const SliceConstants& k, Out& o, float& v) const {
  float low_top, ceiling;
  const int q = lower_pile(p, n, ncount);
  if (q >= 0) {
    low_top = n[q].top;
    // Eq. 32's B_next is the bottom of the span right above the low pile: a
    // body resting on the pile caps it even where its partial bottom voxel
    // lies below T_low, so soil never slides into a pile under a body.
    ceiling = q + 1 < ncount ? n[q + 1].bottom : k.grid_top;
    o.target = static_cast<std::int16_t>(q);
  } else if (p.bottom > 0 && !holds_height(n, ncount, p.bottom)) {
    low_top = p.bottom;  // edge span (fig. 35)
    ceiling = ceiling_above(n, ncount, low_top, k.grid_top);
    o.edge_voxel =
        static_cast<std::int16_t>(std::min<int>(shape_.nz - 1, static_cast<int>(p.bottom)));
  } else {
    v = 0;
    return;
  }
  const double h = k.voxel;
  const float rise = std::min(p.top, ceiling) - low_top;
  const double dx = h * ((d < 4) ? 1.0 : M_SQRT2);
  const auto theta = failure_plane(rise * h, dx, k.cohesion, k.phi, k.gamma);
  if (!theta) {
    v = 0;
    return;
  }
  const double w = wedge_weight(rise * h, dx, *theta, k.gamma);
  v += static_cast<float>(k.gravity * net_force(rise * h, dx, *theta, k.gamma) / w * k.dt);
  const double share = std::min(kMaxShare, v * k.dt / dx);  // eq. 10's v dt / dx
  o.dh = static_cast<float>((rise * h - std::tan(*theta) * dx) * share / h);
}

void Slippage::apply(SoilState& state) const {
  const int nz = shape_.nz;
  tbb::parallel_for(0, shape_.ny, [&](int y) {
    for (int x = 0; x < shape_.nx; ++x) {
      const std::size_t col = static_cast<std::size_t>(y) * shape_.nx + x;
      float* rho = state.rho.data() + col * nz;
      const float* psi = state.psi.data() + col * nz;
      const HeightSpan* spans = spans_.column(col);
      const int count = spans_.count[col];
      float net[HeightSpans::kMaxSpans] = {};
      int pile = 0;
      for (int s = 0; s < count && pile < kMaxPiles; ++s) {
        if (spans[s].type != SpanType::Piled) continue;
        for (int d = 0; d < kDirections; ++d) net[s] -= out_[slot(col, pile, d)].dh;
        ++pile;
      }
      // What the 8 neighbours send here, in a fixed order.
      float edge[kDirections * kMaxPiles];
      int edge_voxel[kDirections * kMaxPiles];
      int edges = 0;
      for (int d = 0; d < kDirections; ++d) {
        const int sx = x - kDx[d], sy = y - kDy[d];  // sender sends along d to us
        if (sx < 0 || sy < 0 || sx >= shape_.nx || sy >= shape_.ny) continue;
        const std::size_t scol = static_cast<std::size_t>(sy) * shape_.nx + sx;
        for (int p = 0; p < kMaxPiles; ++p) {
          const Out& o = out_[slot(scol, p, d)];
          if (o.dh <= 0) continue;
          if (o.target >= 0) {
            net[o.target] += o.dh;
          } else {
            edge[edges] = o.dh;
            edge_voxel[edges++] = o.edge_voxel;
          }
        }
      }
      for (int s = 0; s < count; ++s) {
        const HeightSpan& p = spans[s];
        if (net[s] < 0) {
          const int floor = std::max(0, static_cast<int>(p.bottom));
          remove_down(rho, p.top_voxel, floor, -net[s]);
        } else if (net[s] > 0) {
          add_up(rho, psi, p.top_voxel, nz, net[s]);
        }
      }
      for (int e = 0; e < edges; ++e) add_up(rho, psi, edge_voxel[e], nz, edge[e]);
    }
  });
}

}  // namespace drift::soil
