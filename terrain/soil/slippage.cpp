#include "terrain/soil/slippage.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "terrain/angles.h"
#include "terrain/soil/soil_slice.h"

namespace drift::soil {

namespace {

// Neighbour offsets, paired so that d ^ 1 is the opposite direction: the 4
// faces, the 4 diagonals, the 8 knight's moves.
constexpr int kDx[16] = {1, -1, 0, 0, 1, -1, 1, -1, 2, -2, 1, -1, 2, -2, 1, -1};
constexpr int kDy[16] = {0, 0, 1, -1, 1, -1, -1, 1, 1, -1, 2, -2, -1, 1, -2, 2};
constexpr int kNear = 8;  // directions 0-7 are the adjacent columns
constexpr float kSolid = 1.0f - 1e-5f;

double run_of(int d) { return std::hypot(kDx[d], kDy[d]); }  // in voxels

// The 16 directions in the order of their angle from +x, and the angle from
// each to the next (26.6 and 18.4 degrees in turn).
constexpr int kByAngle[16] = {0, 8, 4, 10, 2, 15, 7, 13, 1, 9, 5, 11, 3, 14, 6, 12};
const double kGap[16] = {
    std::atan(0.5), M_PI / 4 - std::atan(0.5), M_PI / 4 - std::atan(0.5), std::atan(0.5),
    std::atan(0.5), M_PI / 4 - std::atan(0.5), M_PI / 4 - std::atan(0.5), std::atan(0.5),
    std::atan(0.5), M_PI / 4 - std::atan(0.5), M_PI / 4 - std::atan(0.5), std::atan(0.5),
    std::atan(0.5), M_PI / 4 - std::atan(0.5), M_PI / 4 - std::atan(0.5), std::atan(0.5)};

std::size_t slot(std::size_t column, int pile, int dir) {
  return (column * Slippage::kMaxPiles + pile) * Slippage::kDirections + dir;
}

// Largest drop (voxels) from a pile's bottom to a neighbour's pile that
// still counts as one continuous slope of the ground rather than an edge.
// A DEM or voxel terrain steeper than 45 degrees is a staircase of one-voxel
// steps (more along a knight's run): with eq. 31's overlap alone, thin soil
// on each step met its lower neighbour only through a zero-height edge span
// at its own bottom, so only its thickness counted and it lay on the
// mountainside as a blanket instead of sliding (issue 33, item 6). A
// body's top (a block, a blade) stands higher above its neighbours and
// keeps the thesis's edge span (fig. 35).
constexpr float kGroundStep = 2.5f;

// The lower pile of column n that pile p slides onto: the highest pile below
// p's top that meets it (eq. 31, >= 0), or one at most kGroundStep below
// p's bottom with nothing above it up to p's top. -1 if none.
int lower_pile(const HeightSpan& p, const HeightSpan* n, int count) {
  int best = -1;
  for (int q = 0; q < count; ++q) {
    if (n[q].type != SpanType::Piled || n[q].top >= p.top) continue;
    const float above = q + 1 < count ? n[q + 1].bottom : 1e30f;
    if (std::min(p.top, n[q].top) - std::max(p.bottom, n[q].bottom) >= 0 ||
        (n[q].top >= p.bottom - kGroundStep && above >= p.top))
      best = q;
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

// Removes `amount` of soil from voxel `top` downwards (not below `floor`);
// the soil leaves with its voxel's moisture. Returns the water (soil times
// moisture) removed; `lowest` is the lowest voxel it took from.
double remove_down(float* rho, const float* wet, int top, int floor, float amount, int& lowest) {
  double water = 0;
  lowest = top;
  for (int z = top; z >= floor && amount > 0; --z) {
    const float take = std::min(rho[z], amount);
    rho[z] -= take;
    amount -= take;
    water += static_cast<double>(take) * wet[z];
    lowest = z;
  }
  return water;
}

// Adds `amount` of soil of moisture `m` from voxel `from` upwards into the
// room left by soil and body, up to the first solid body voxel (soil never
// passes through a body); what finds no room stays in the last open voxel
// (mass is kept; the settle after the slippage sends it sideways: returns
// true then). Each voxel's moisture becomes the mass-weighted mean of what
// it held and what came.
bool add_up(float* rho, float* wet, const float* psi, int from, int nz, float amount, float m) {
  int last = std::clamp(from, 0, nz - 1);
  for (int z = last; z < nz && amount > 0; ++z) {
    if (psi[z] >= kSolid && z > from) break;
    last = z;
    const float put = std::min(amount, std::max(0.0f, 1.0f - psi[z] - rho[z]));
    if (put > 0) wet[z] = mix_moisture(rho[z], wet[z], put, m);
    rho[z] += put;
    amount -= put;
  }
  if (amount <= 0) return false;
  wet[last] = mix_moisture(rho[last], wet[last], amount, m);
  rho[last] += amount;
  return true;
}

}  // namespace

std::uint64_t soil_run_bytes(const terrain::Grid3Shape& shape) {
  // The surface (surface.cpp): the straightened density and its copy padded
  // one voxel deeper, 8 B a voxel, then OpenVDB's volumeToMesh and the mesh.
  // A surface crossing each column twice (the soil's top and the floor) gives
  // 4 triangles a column; measured, they cost 270 B a column at the peak.
  constexpr std::uint64_t kSurfaceVoxel = 2 * sizeof(float), kSurfaceColumn = 288;
  constexpr std::uint64_t kHeightsColumn = sizeof(float);  // a DEM's terrain heights
  const auto columns = static_cast<std::uint64_t>(shape.nx) * static_cast<std::uint64_t>(shape.ny);
  return soil_state_bytes(shape) + static_cast<std::uint64_t>(shape.count()) * kSurfaceVoxel +
         columns * (Slippage::bytes_per_column() + kSurfaceColumn + kHeightsColumn);
}

std::uint64_t Slippage::bytes_per_column() {
  return HeightSpans::kMaxSpans * sizeof(HeightSpan) + 2 * sizeof(std::uint8_t) +
         kMaxPiles * (kDirections * sizeof(Out) + 2 * sizeof(float) + sizeof(std::int8_t) +
                      5 * sizeof(int));
}

Slippage::Slippage(const terrain::Grid3Shape& shape)
    : shape_(shape),
      out_(shape.columns() * kMaxPiles * kDirections),
      speed_(shape.columns() * kMaxPiles, 0.0f),
      pile_span_(shape.columns() * kMaxPiles, -1),
      down_(shape.columns() * kMaxPiles, -1),
      up_(shape.columns() * kMaxPiles, -1),
      toe_(shape.columns() * kMaxPiles),
      crest_(shape.columns() * kMaxPiles),
      hop_(shape.columns() * kMaxPiles),
      rest_(shape.columns() * kMaxPiles, 0.0f),
      pile_wet_(shape.columns() * kMaxPiles, 0.0f),
      out_wet_(shape.columns() * kMaxPiles, 0.0f),
      out_from_(shape.columns() * kMaxPiles, -1),
      overfilled_(shape.columns(), 0),
      sends_(shape.columns(), 0) {}

void Slippage::step(SoilState& state, const SoilType& soil, double gravity, double dt) {
  build_height_spans(shape_, state.rho, state.psi, spans_);
  link_piles();
  pile_moisture(state);
  rest_angles(soil);
  compute_slices(soil, gravity, dt);
  apply(state);
}

double Slippage::rest_angle_of(std::size_t column, int pile) const {
  const std::size_t node = column * kMaxPiles + pile;
  return pile_span_[node] < 0 ? -1.0 : rest_[node];
}

void Slippage::pile_moisture(const SoilState& state) {
  const int nz = shape_.nz;
  tbb::parallel_for(std::size_t{0}, pile_wet_.size(), [&](std::size_t node) {
    pile_wet_[node] = 0;
    if (pile_span_[node] < 0) return;
    const std::size_t col = node / kMaxPiles;
    const HeightSpan& p = spans_.column(col)[pile_span_[node]];
    const float* rho = state.rho.data() + col * nz;
    const float* wet = state.wet.data() + col * nz;
    // The moisture of the pile's upper third (at least its top voxel): the
    // sliding wedge lies above the failure plane, which through a flank's
    // columns passes under their upper part, so water that drained to the
    // pile's foot no longer holds its top (issue 33, item 3).
    double soil = 0, water = 0;
    const int bottom = std::max(0, static_cast<int>(p.bottom));
    const int upper = std::max(bottom, p.top_voxel - (p.top_voxel - bottom + 1) / 3);
    for (int z = upper; z <= p.top_voxel; ++z) {
      soil += rho[z];
      water += static_cast<double>(rho[z]) * wet[z];
    }
    pile_wet_[node] = soil > 0 ? static_cast<float>(water / soil) : 0.0f;
  });
}

void Slippage::link_piles() {
  const int nx = shape_.nx, ny = shape_.ny;
  tbb::parallel_for(0, ny, [&](int y) {
    for (int x = 0; x < nx; ++x) {
      const std::size_t col = static_cast<std::size_t>(y) * nx + x;
      const HeightSpan* spans = spans_.column(col);
      int pile = 0;
      for (int s = 0; s < spans_.count[col] && pile < kMaxPiles; ++s)
        if (spans[s].type == SpanType::Piled)
          pile_span_[col * kMaxPiles + pile++] = static_cast<std::int8_t>(s);
      for (; pile < kMaxPiles; ++pile) pile_span_[col * kMaxPiles + pile] = -1;
    }
  });
  // The node of span s of column col, -1 if it is not one of its sliding piles.
  auto node_of = [&](std::size_t col, int s) -> int {
    for (int k = 0; k < kMaxPiles; ++k)
      if (pile_span_[col * kMaxPiles + k] == s) return static_cast<int>(col * kMaxPiles + k);
    return -1;
  };
  tbb::parallel_for(0, ny, [&](int y) {
    for (int x = 0; x < nx; ++x) {
      const std::size_t col = static_cast<std::size_t>(y) * nx + x;
      for (int k = 0; k < kMaxPiles; ++k) {
        const std::size_t node = col * kMaxPiles + k;
        down_[node] = up_[node] = -1;
        if (pile_span_[node] < 0) continue;
        const HeightSpan& p = spans_.column(col)[pile_span_[node]];
        double steepest_down = 0, steepest_up = 0;
        for (int d = 0; d < kNear; ++d) {
          const int ax = x + kDx[d], ay = y + kDy[d];
          if (ax < 0 || ay < 0 || ax >= nx || ay >= ny) continue;
          const std::size_t ncol = static_cast<std::size_t>(ay) * nx + ax;
          const HeightSpan* n = spans_.column(ncol);
          const int count = spans_.count[ncol];
          // Down: only a pile that holds soil belongs to a slope and leads on.
          const int q = p.soil >= kSlopeSoil ? lower_pile(p, n, count) : -1;
          const int qn = q >= 0 ? node_of(ncol, q) : -1;
          if (qn >= 0) {
            const double slope = (p.top - n[q].top) / run_of(d);
            if (slope > steepest_down) steepest_down = slope, down_[node] = qn;
          }
          // Up: a neighbour pile holding soil that would slide onto this one.
          for (int s = 0; s < count; ++s) {
            if (n[s].type != SpanType::Piled || n[s].soil < kSlopeSoil || n[s].top <= p.top)
              continue;
            const int jn = node_of(ncol, s);
            if (jn < 0 ||
                lower_pile(n[s], spans_.column(col), spans_.count[col]) != pile_span_[node])
              continue;
            const double slope = (n[s].top - p.top) / run_of(d);
            if (slope > steepest_up) steepest_up = slope, up_[node] = jn;
          }
        }
      }
    }
  });
}

namespace {

// Follows `link` to its end from every node by pointer doubling (the chains
// strictly descend or ascend, so they end): end[i] = the last node of i's
// chain. Parallel rounds over double buffers: the same result on any thread
// count.
void chain_ends(const std::vector<int>& link, std::vector<int>& end, std::vector<int>& scratch) {
  const std::size_t n = link.size();
  tbb::parallel_for(std::size_t{0}, n,
                    [&](std::size_t i) { end[i] = link[i] >= 0 ? link[i] : static_cast<int>(i); });
  for (;;) {
    std::atomic<bool> changed{false};
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
      scratch[i] = end[end[i]];
      if (scratch[i] != end[i]) changed.store(true, std::memory_order_relaxed);
    });
    end.swap(scratch);
    if (!changed) return;
  }
}

}  // namespace

void Slippage::rest_angles(const SoilType& soil) {
  std::vector<int> scratch(toe_.size());
  chain_ends(down_, toe_, scratch);
  chain_ends(up_, crest_, scratch);
  const double h = shape_.voxel_size, phi = terrain::radians(soil.phi_deg);
  auto top = [&](std::size_t node) {
    return spans_.column(node / kMaxPiles)[pile_span_[node]].top;
  };
  tbb::parallel_for(std::size_t{0}, rest_.size(), [&](std::size_t i) {
    if (pile_span_[i] < 0) return;
    const HeightSpan& p = spans_.column(i / kMaxPiles)[pile_span_[i]];
    // The slope's real height: crest to toe, at least the pile's own height.
    const double rise = std::max(top(crest_[i]) - top(toe_[i]), p.top - p.bottom) * h;
    // The pile's own moisture gives its apparent cohesion (thesis 5.3.4).
    rest_[i] = static_cast<float>(
        rest_angle(rise, soil.effective_cohesion(pile_wet_[i]), phi, soil.gamma));
  });
}

void Slippage::compute_slices(const SoilType& soil, double gravity, double dt) {
  const SliceConstants k{shape_.voxel_size, soil.gamma, gravity, dt, static_cast<float>(shape_.nz)};
  tbb::parallel_for(0, shape_.ny, [&](int y) {
    for (int x = 0; x < shape_.nx; ++x) {
      const std::size_t col = static_cast<std::size_t>(y) * shape_.nx + x;
      for (int pile = 0; pile < kMaxPiles; ++pile) {
        // An int8_t span index, -1 for none: its sign is meant.
        // NOLINTNEXTLINE(bugprone-signed-char-misuse)
        const int s = pile_span_[col * kMaxPiles + pile];
        if (s >= 0) {
          slide_pile(x, y, pile, spans_.column(col)[s], k);
          continue;
        }
        for (int d = 0; d < kDirections; ++d) out_[slot(col, pile, d)] = Out{};
        speed_[col * kMaxPiles + pile] = 0;
      }
    }
  });
}

bool Slippage::open_path(int x, int y, int d, const HeightSpan& p) const {
  const int sx = kDx[d] > 0 ? 1 : -1, sy = kDy[d] > 0 ? 1 : -1;
  const bool along_x = std::abs(kDx[d]) == 2;
  const int cross[2][2] = {{x + sx, along_x ? y : y + sy}, {along_x ? x + sx : x, y + sy}};
  for (const auto& c : cross) {
    const std::size_t col = static_cast<std::size_t>(c[1]) * shape_.nx + c[0];
    const HeightSpan* n = spans_.column(col);
    const int count = spans_.count[col];
    const int q = lower_pile(p, n, count);
    if (q < 0) return false;
    const float ceiling = q + 1 < count ? n[q + 1].bottom : static_cast<float>(shape_.nz);
    if (ceiling < p.top) return false;
  }
  return true;
}

void Slippage::slide_pile(int x, int y, int pile, const HeightSpan& p, const SliceConstants& k) {
  const std::size_t col = static_cast<std::size_t>(y) * shape_.nx + x;
  const std::size_t node = col * kMaxPiles + pile;
  const double rest = rest_[node];
  float& v = speed_[node];
  // Each direction's slice: its target and its slope (rise over run), -1
  // where no slice can form.
  double slope[kDirections];
  for (int d = 0; d < kDirections; ++d) {
    Out& o = out_[slot(col, pile, d)];
    o = Out{};
    slope[d] = -1;
    const int nx = x + kDx[d], ny = y + kDy[d];
    if (nx < 0 || ny < 0 || nx >= shape_.nx || ny >= shape_.ny ||
        (d >= kNear && !open_path(x, y, d, p)))
      continue;
    const std::size_t ncol = static_cast<std::size_t>(ny) * shape_.nx + nx;
    const double rise = slice_rise(p, spans_.column(ncol), spans_.count[ncol], k, o);
    if (rise > 0) slope[d] = rise / run_of(d);
  }
  // The steepest descent: along one direction, or between two neighbouring
  // ones (a plane through both slices, D-infinity's facets, Tarboton 1997):
  // with slopes s1, s2 along directions Delta apart, the plane's gradient
  // lies at a from the first, tan(a) = (s2 / s1 - cos(Delta)) / sin(Delta),
  // and is s1 / cos(a) steep.
  double steepest = 0, along = 0;
  int d1 = -1, d2 = -1;
  for (int i = 0; i < kDirections; ++i) {
    const int a = kByAngle[i], b = kByAngle[(i + 1) % kDirections];
    if (slope[a] > steepest) steepest = slope[a], d1 = a, d2 = -1, along = 0;
    if (slope[a] <= 0 || slope[b] <= 0) continue;
    const double gap = kGap[i];
    const double t = (slope[b] / slope[a] - std::cos(gap)) / std::sin(gap);
    if (!(t > 0) || std::atan(t) >= gap) continue;
    const double g = slope[a] * std::sqrt(1 + t * t);
    if (g > steepest) steepest = g, d1 = a, d2 = b, along = std::atan(t);
  }
  // Failure of the slope along its steepest descent, over one voxel's run;
  // once stopped, only above the static angle.
  const double h = k.voxel;
  const double margin = terrain::radians(v > 0 ? kStopDeg : kStaticDeg);
  const double wedge = (steepest - std::tan(rest)) * h;  // above the rest plane, m
  if (d1 < 0 || std::atan(steepest) <= rest + margin || (v > 0 && wedge <= kStopHeight)) {
    v = 0;
    return;
  }
  const double rise = steepest * h;
  v += static_cast<float>(k.gravity * net_force(rise, h, rest, k.gamma) /
                          wedge_weight(rise, h, rest, k.gamma) * k.dt);
  // Eq. 10's height over one voxel's run, as a flux: soil times the distance
  // it travels. Split between the two directions bracketing the descent so
  // that the flux points down the true gradient, and each direction gets
  // its share over its own run (a knight's move carries it sqrt(5) voxels):
  // no lattice direction is preferred.
  const double flux = wedge * std::min(kMaxShare, v * k.dt / h) / h;  // voxels x voxels
  double w1 = 1, w2 = 0;
  if (d2 >= 0) {
    const double gap = std::atan2(kDy[d2], kDx[d2]) - std::atan2(kDy[d1], kDx[d1]);
    const double sg = std::sin(std::remainder(gap, 2 * M_PI));
    w1 = std::sin(std::remainder(gap, 2 * M_PI) - along) / sg;
    w2 = std::sin(along) / sg;
  }
  double total = flux * w1 / run_of(d1);
  out_[slot(col, pile, d1)].dh = static_cast<float>(flux * w1 / run_of(d1));
  if (d2 >= 0) {
    out_[slot(col, pile, d2)].dh = static_cast<float>(flux * w2 / run_of(d2));
    total += flux * w2 / run_of(d2);
  }
  // A pile cannot give more soil than it holds.
  if (total > p.soil && total > 0) {
    const float scale = static_cast<float>(p.soil / total * (1.0 - 1e-6));
    for (int d = 0; d < kDirections; ++d) out_[slot(col, pile, d)].dh *= scale;
  }
}

double Slippage::slice_rise(const HeightSpan& p, const HeightSpan* n, int ncount,
                            const SliceConstants& k, Out& o) const {
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
    return 0;
  }
  return std::min(p.top, ceiling) - low_top;  // eq. 32, voxels
}

void Slippage::apply(SoilState& state) {
  const int nz = shape_.nz;
  // First every pile gives what its slices carry away, from its top down,
  // and notes the moisture of the soil that left (what it sends carries it).
  tbb::parallel_for(0, shape_.ny, [&](int y) {
    for (int x = 0; x < shape_.nx; ++x) {
      const std::size_t col = static_cast<std::size_t>(y) * shape_.nx + x;
      float* rho = state.rho.data() + col * nz;
      const float* wet = state.wet.data() + col * nz;
      const HeightSpan* spans = spans_.column(col);
      bool gives = false;
      for (int pile = 0; pile < kMaxPiles; ++pile) {
        const std::size_t node = col * kMaxPiles + pile;
        out_from_[node] = -1;
        // NOLINTNEXTLINE(bugprone-signed-char-misuse): an int8_t index, -1 none
        const int s = pile_span_[node];
        if (s < 0) continue;  // its slots hold dh = 0 (compute_slices)
        float out = 0;
        for (int d = 0; d < kDirections; ++d) {
          const float dh = out_[slot(col, pile, d)].dh;
          out += dh;
          gives |= dh > 0;
        }
        if (out <= 0) continue;
        const HeightSpan& p = spans[s];
        const double water = remove_down(
            rho, wet, p.top_voxel, std::max(0, static_cast<int>(p.bottom)), out, out_from_[node]);
        out_wet_[node] = static_cast<float>(water / out);
      }
      sends_[col] = gives;
    }
  });
  // Then every pile gathers what its 16 neighbours send, in a fixed order,
  // and lays it on from the lowest voxel it gave from.
  tbb::parallel_for(0, shape_.ny, [&](int y) {
    for (int x = 0; x < shape_.nx; ++x) {
      const std::size_t col = static_cast<std::size_t>(y) * shape_.nx + x;
      float* rho = state.rho.data() + col * nz;
      float* wet = state.wet.data() + col * nz;
      const float* psi = state.psi.data() + col * nz;
      const HeightSpan* spans = spans_.column(col);
      const int count = spans_.count[col];
      bool over = false;
      float in[HeightSpans::kMaxSpans] = {};
      double in_water[HeightSpans::kMaxSpans] = {};
      float edge[kDirections * kMaxPiles], edge_wet[kDirections * kMaxPiles];
      int edge_voxel[kDirections * kMaxPiles];
      int edges = 0;
      for (int d = 0; d < kDirections; ++d) {
        const int sx = x - kDx[d], sy = y - kDy[d];  // sender sends along d to us
        if (sx < 0 || sy < 0 || sx >= shape_.nx || sy >= shape_.ny) continue;
        const std::size_t scol = static_cast<std::size_t>(sy) * shape_.nx + sx;
        // Most columns give nothing: their 64 slots are not read (what is
        // skipped has dh <= 0, so the sums keep their order and bits).
        if (!sends_[scol]) continue;
        for (int p = 0; p < kMaxPiles; ++p) {
          const Out& o = out_[slot(scol, p, d)];
          if (o.dh <= 0) continue;
          const float m = out_wet_[scol * kMaxPiles + p];
          if (o.target >= 0) {
            in[o.target] += o.dh;
            in_water[o.target] += static_cast<double>(o.dh) * m;
          } else {
            edge[edges] = o.dh;
            edge_wet[edges] = m;
            edge_voxel[edges++] = o.edge_voxel;
          }
        }
      }
      for (int s = 0; s < count; ++s) {
        if (in[s] <= 0) continue;
        int from = spans[s].top_voxel;
        for (int pile = 0; pile < kMaxPiles; ++pile)
          if (pile_span_[col * kMaxPiles + pile] == s && out_from_[col * kMaxPiles + pile] >= 0)
            from = out_from_[col * kMaxPiles + pile];
        over |= add_up(rho, wet, psi, from, nz, in[s],
                       std::clamp(static_cast<float>(in_water[s] / in[s]), 0.0f, 1.0f));
      }
      for (int e = 0; e < edges; ++e)
        over |= add_up(rho, wet, psi, edge_voxel[e], nz, edge[e], edge_wet[e]);
      overfilled_[col] = over;
    }
  });
  any_overfilled_ = std::find(overfilled_.begin(), overfilled_.end(), 1) != overfilled_.end();
}

}  // namespace drift::soil
