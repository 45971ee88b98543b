#include "dunes/sand_model.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>
#include <vector>

#include "dunes/avalanche.h"
#include "dunes/height_range.h"
#include "dunes/lattice.h"
#include "dunes/sand_parameters.h"
#include "dunes/sweep_tiles.h"
#include "dunes/wind_frame.h"
#include "terrain/angles.h"
#include "terrain/error.h"
#include "terrain/hash.h"
#include "terrain/memory.h"
#include "terrain/parameter.h"
#include "terrain/simd.h"

namespace drift::dunes {

namespace {

// Relaxation sweeps per time step: saltation steepens slopes a little each
// step, and a few sweeps keep them at the angle of repose as the sand moves.
constexpr int kSweepsPerStep = 4;
// At the end, relax fully (to a thousandth of a height unit).
constexpr int kFinalSweeps = 20000;

// tanh by its [7/6] Pade approximant (Lambert's continued fraction), within
// 2e-7 for |x| < 4.97 and clamped to +-1 beyond, where tanh is 1 within 1e-4:
// a third of the time of libm's tanhf, and the same bits everywhere. Branch
// free (selects), so loops over it vectorise.
DRIFT_SIMD_KERNEL float fast_tanh(float x) {
  const float above = x > -4.97f ? x : -4.97f;
  const float c = above < 4.97f ? above : 4.97f;
  const float x2 = c * c;
  const float p = c * (135135.0f + x2 * (17325.0f + x2 * (378.0f + x2)));
  const float q = 135135.0f + x2 * (62370.0f + x2 * (3150.0f + x2 * 28.0f));
  const float r = p / q;
  return std::fabs(x) > 4.97f ? std::copysign(1.0f, x) : r;
}

// The largest edge drop avalanching allows, in model height units.
double max_drop(const SandOptions& o) {
  return terrain::tan_degrees(o.repose_deg) * o.cell_m / o.height_unit;
}

// The shadow line's fall per cell along the wind, in model height units.
double shadow_drop(const SandOptions& o) {
  return terrain::tan_degrees(o.shadow_deg) * o.cell_m / o.height_unit;
}

}  // namespace

void validate(const SandOptions& o) {
  for (const terrain::Parameter<SandOptions>& p : sand_parameters()) p.require(o);
  if (o.model == Model::Dunes) {
    if (o.L0 <= o.b)
      throw terrain::ParameterError("L0",
                                    "must exceed b for dunes, or windward flights go backwards");
    if (o.q <= o.b_prime)
      throw terrain::ParameterError("q",
                                    "must exceed b_prime for dunes, or the lift turns negative");
  }
  const std::uint64_t cells = static_cast<std::uint64_t>(o.size) * o.size;
  // Heights and the next field (saltation, creep, avalanching) on the wind
  // lattice (at most as many points as the grid; the wind shadow is a bit a
  // point), then the field turned to the grid: 12 bytes a cell, measured 10-11
  // (drift dunes --snapshot-every counts its snapshots on top).
  require_memory(cells * (4 + 4 + 4), "the sand grid", "choose a smaller size");
}

terrain::HeightField initial_field(const SandOptions& o) {
  const WindLattice l = wind_lattice(o.wind_from_deg, o.size);
  terrain::HeightField h(l.columns, l.rows, 0.0f, terrain::local_georeference(o.cell_m));
  const std::uint64_t key = terrain::mix64(o.seed);
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double u = terrain::unit_double(terrain::mix64(key ^ terrain::mix64(i)));
    h.values()[i] = static_cast<float>(u * o.initial_amplitude);
  }
  return h;
}

namespace {

// How saltation's landings are summed. The sand lives on the wind lattice
// (dunes/wind_frame.h), whose rows are the wind lines and close on
// themselves, so a flight lands on its own row, shared linearly between the
// two points around the landing (as the paper has it along x). Each row's
// landings are summed in double precision in a private window in a fixed
// order, and each point is rounded to float once, so mass is kept to float
// rounding and the bits do not depend on the thread count.
//
// Flight lengths and slopes are in grid cells, as in the paper; the
// lattice's columns are h cells apart: `per_cell` = 1 / h columns a cell.

// Whether a step needs the field's height range: the ripples' longest
// flight and the wind shadow's reach upwind do.
bool needs_height_range(const SandOptions& o) {
  return o.model == Model::Ripples || o.shadow_deg > 0.0;
}

// The longest flight, in cells, short of a lap of a row `width` points long
// (`range`: the field's, for ripples).
double max_flight(const SandOptions& o, double per_cell, int width, HeightRange range) {
  double longest = o.L0 + o.b;  // dunes: L0 - b tanh(.) <= L0 + b
  if (o.model == Model::Ripples) longest = o.L0 + o.b * range.hi;
  return std::clamp(longest, 0.0, (width - 1.0) / per_cell);
}

// What the flight kernel needs, in float: flights of a few tens of columns
// keep 1e-6 of a column, and the sand each carries is summed in double.
struct FlightParams {
  float L0, b, q, b_prime;
  float per_cell;     // columns per cell along the wind
  float max_columns;  // the longest flight, in columns (< the row's width)
};

// The flights of one row of n points (`c` its heights; `before` the point
// before the first column and `after` the one after the last: the row's last
// and first): point x lifts part[x], which lands land[x] + f columns on,
// unwrapped (land[x] = x + the whole columns, < 2n - 1); to_next[x] is the
// share f * part[x] of the point one further on. Paper eq. 1 (ripples:
// L = L0 + b H, q) or eqs. 2-3 (dunes: L = L0 - b tanh(dH/dx), q + b'
// tanh(dH/dx)), dH/dx the central difference between the point's neighbours
// on its wind line, a column (1 / per_cell cells) either side: the gradient
// of 4 grid neighbours dotted with the wind would take an oblique slope from
// the neighbouring lines only, blind to the point's own (docs/dunes.md).
//
// In the wind shadow (Werner 1995; `shadow` as wind_shadow() fills it)
// nothing is lifted, and flights into it are caught at its edge; past it the
// lift is scaled by its `recovery` (shadow_recovery()). Rows without a
// shadow pass a map with no shadow in reach and a recovery of 1. One pass,
// branch free (selects), so that the loop vectorises; the scattering adds
// are left to fly().
template <Model kModel>
DRIFT_SIMD_KERNEL void flights_kernel(const float* __restrict c, int n, float before, float after,
                                      const FlightParams& p, const std::uint16_t* __restrict shadow,
                                      const float* __restrict recovery,
                                      std::int32_t* __restrict land, float* __restrict part,
                                      float* __restrict to_next) {
  // Parameters as locals: the outputs could alias them otherwise.
  const float L0 = p.L0, b = p.b, q = p.q, b_prime = p.b_prime, per_cell = p.per_cell;
  const float max_columns = p.max_columns;
  auto flight = [&](int x, float upwind, float downwind) {
    float length, lift;
    if constexpr (kModel == Model::Dunes) {
      const float g = fast_tanh(per_cell * (0.5f * (downwind - upwind)));
      length = L0 - b * g;
      lift = q + b_prime * g;
    } else {
      length = L0 + b * c[x];
      lift = q;
    }
    const int s = shadow[x];
    const float along = length * per_cell;
    const float positive = along > 0.0f ? along : 0.0f;
    const float bounded = positive < max_columns ? positive : max_columns;
    const float to_shadow = static_cast<float>(columns_to_shadow(s));
    const float columns = bounded < to_shadow ? bounded : to_shadow;
    // Times 1 or 0 (lifts are >= 0, so exact; GCC vectorises it, unlike a
    // select).
    const float lifted = lift * static_cast<float>(lit(s)) * recovery[x];
    const int whole = static_cast<int>(columns);
    land[x] = x + whole;
    part[x] = lifted;
    to_next[x] = lifted * (columns - static_cast<float>(whole));
  };
  flight(0, before, c[1]);
  for (int x = 1; x + 1 < n; ++x) flight(x, c[x - 1], c[x + 1]);
  flight(n - 1, c[n - 2], after);
}
DRIFT_SIMD_TWINS(ripple_flights, flights_kernel<Model::Ripples>,
                 (const float* c, int n, float before, float after, const FlightParams& p,
                  const std::uint16_t* shadow, const float* recovery, std::int32_t* land,
                  float* part, float* to_next),
                 (c, n, before, after, p, shadow, recovery, land, part, to_next))
DRIFT_SIMD_TWINS(dune_flights, flights_kernel<Model::Dunes>,
                 (const float* c, int n, float before, float after, const FlightParams& p,
                  const std::uint16_t* shadow, const float* recovery, std::int32_t* land,
                  float* part, float* to_next),
                 (c, n, before, after, p, shadow, recovery, land, part, to_next))

// Per-row scratch of saltation: the lift's recovery past shadows, the
// flights, and the two windows the row's sand is summed in (fly(); the odd
// one is left all 0 for the next row); for rows without a shadow, a map
// with none in reach and a recovery of 1.
struct RowScratch {
  std::vector<float> recovery;
  std::vector<std::int32_t> land;
  std::vector<float> part, to_next;
  std::vector<double> even, odd;
  std::vector<std::uint16_t> no_shadow;
  std::vector<float> full_lift;
  void resize(int n) {
    const auto size = static_cast<std::size_t>(n);
    for (auto* v : {&recovery, &part, &to_next}) v->resize(size);
    land.resize(size);
    even.resize(2 * size);
    if (odd.size() != 2 * size) odd.assign(2 * size, 0.0);
    if (no_shadow.size() != size) no_shadow.assign(size, std::uint16_t{0xfffe});
    if (full_lift.size() != size) full_lift.assign(size, 1.0f);
  }
};

// A row's sand after its flights, into `out` (its n points): each point
// less what it lifts, plus what lands on it, summed in double and rounded
// once. Landings past the row's end (at most `tail` points) are summed
// beyond it and then folded onto its start, so the adds need no wrapping
// test. Their time is the chain of adds to the same few points
// (neighbouring flights land side by side, and those caught at a shadow's
// edge on one point), so even and odd sources land in two windows, two
// chains side by side, summed at the end. A share is exact in double:
// part - to_next of two floats, and both added, so what lands is what was
// lifted.
void fly(const float* c, int n, int tail, RowScratch& f, float* __restrict out) {
  const std::int32_t* __restrict land = f.land.data();
  const float* __restrict part = f.part.data();
  const float* __restrict to_next = f.to_next.data();
  double* __restrict even = f.even.data();
  double* __restrict odd = f.odd.data();
  for (int x = 0; x < n; ++x) even[x] = static_cast<double>(c[x]) - part[x];
  std::fill(even + n, even + n + tail, 0.0);
  auto land_in = [&](double* window, int x) {
    const double next = to_next[x];
    window[land[x]] += static_cast<double>(part[x]) - next;
    window[land[x] + 1] += next;
  };
  int x = 0;
  for (; x + 1 < n; x += 2) {
    land_in(even, x);
    land_in(odd, x + 1);
  }
  if (x < n) land_in(even, x);
  // Summed, folded and rounded in one pass, which leaves `odd` all 0.
  for (int i = 0; i < tail; ++i) {
    out[i] = static_cast<float>((even[i] + odd[i]) + (even[n + i] + odd[n + i]));
    odd[i] = 0.0;
    odd[n + i] = 0.0;
  }
  for (int i = tail; i < n; ++i) {
    out[i] = static_cast<float>(even[i] + odd[i]);
    odd[i] = 0.0;
  }
}

// What saltation needs to know once per step.
struct SaltationPlan {
  FlightParams flights{};
  int tail = 0;  // points past a row's end that landings reach (see fly())
  const ShadowMap* shadow = nullptr;
  double reattach = 0.0;  // with a shadow: see shadow_recovery()
};

// One row's sand after saltation, into `out` (see fly()).
void saltate_row(const terrain::HeightField& h, const SandOptions& o, const SaltationPlan& p,
                 int row, RowScratch& scratch, float* out) {
  const int n = h.width();
  const float* c = &h(0, row);
  const std::uint16_t* shadow = scratch.no_shadow.data();
  const float* recovery = scratch.full_lift.data();
  if (p.shadow) {
    shadow = p.shadow->data() + static_cast<std::size_t>(row) * n;
    if (p.reattach > 0.0) {
      line_recovery(shadow, n, p.reattach, scratch.recovery.data());
      recovery = scratch.recovery.data();
    }
  }
  auto* flights = o.model == Model::Dunes ? dune_flights : ripple_flights;
  flights(c, n, c[n - 1], c[0], p.flights, shadow, recovery, scratch.land.data(),
          scratch.part.data(), scratch.to_next.data());
  fly(c, n, p.tail, scratch, out);
}

// Rows [begin, end), each in turn, into `out`.
void land_rows(const terrain::HeightField& h, const SandOptions& o, const SaltationPlan& p,
               int begin, int end, std::vector<float>& out) {
  const int n = h.width();
  thread_local RowScratch scratch;
  scratch.resize(n);
  for (int r = begin; r < end; ++r) {
    saltate_row(h, o, p, r, scratch, &out[static_cast<std::size_t>(r) * n]);
  }
}

// Saltation on a lattice `per_cell` columns a grid cell along the wind.
void saltate_on(terrain::HeightField& h, const SandOptions& o, double per_cell, Workspace& w) {
  const int rows = h.height();
  // One pass for both the longest flight and the shadow.
  const HeightRange range = needs_height_range(o) ? height_range(h) : HeightRange{0.0f, 0.0f};
  // The longest flight in columns, as the kernel bounds it.
  const double longest = max_flight(o, per_cell, h.width(), range);
  const auto max_columns =
      std::min(static_cast<float>(longest * per_cell), static_cast<float>(h.width() - 1));
  SaltationPlan p;
  p.flights = FlightParams{.L0 = static_cast<float>(o.L0),
                           .b = static_cast<float>(o.b),
                           .q = static_cast<float>(o.q),
                           .b_prime = static_cast<float>(o.b_prime),
                           .per_cell = static_cast<float>(per_cell),
                           .max_columns = max_columns};
  // land + 1 <= n - 1 + floor(max_columns) + 1.
  p.tail = static_cast<int>(max_columns) + 1;
  if (o.shadow_deg > 0.0) {
    // The shadow is needed as far ahead as the longest flight reaches; its
    // line falls shadow_drop per cell, so per column 1 / per_cell times that.
    wind_shadow(h, range, shadow_drop(o) / per_cell, longest * per_cell, w.shadow);
    p.shadow = &w.shadow;
    p.reattach = o.reattach;
  }
  w.next.resize(h.size());
  // Rows are independent, so no partition changes a bit: tasks of some 16k
  // points, one row each on a wind lattice's long rows.
  const int rows_per_task = std::clamp(16384 / h.width(), 1, 16);
  const int tasks = (rows + rows_per_task - 1) / rows_per_task;
  tbb::parallel_for(
      0, tasks,
      [&](int i) {
        land_rows(h, o, p, i * rows_per_task, std::min(rows, (i + 1) * rows_per_task), w.next);
      },
      tbb::simple_partitioner());
  std::swap(w.next, h.values());
}

// Creep at a point: the sum of edge fluxes d * (neighbour - centre),
// antisymmetric per edge, so mass is conserved.
DRIFT_SIMD_KERNEL float crept(float centre, float west, float east, float north, float south,
                              float d) {
  return centre + d * ((west - centre) + (east - centre) + (north - centre) + (south - centre));
}

// Creep on the strip [x0, x1) of row c (n and s the rows north and south of
// it).
DRIFT_SIMD_KERNEL void creep_strip_kernel(const float* __restrict c, const float* __restrict n,
                                          const float* __restrict s, int w, int x0, int x1, float d,
                                          float* __restrict out) {
  const InnerColumns inner = inner_columns(x0, x1, w);
  for (int x = inner.begin; x < inner.end; ++x) {
    out[x] = crept(c[x], c[x - 1], c[x + 1], n[x], s[x], d);
  }
  for_wrapped_columns(x0, x1, w, [&](int x, int west, int east) {
    out[x] = crept(c[x], c[west], c[east], n[x], s[x], d);
  });
}
DRIFT_SIMD_TWINS(creep_strip, creep_strip_kernel,
                 (const float* c, const float* n, const float* s, int w, int x0, int x1, float d,
                  float* out),
                 (c, n, s, w, x0, x1, d, out))

}  // namespace

void saltate(terrain::HeightField& h, const SandOptions& o, Workspace& w) {
  saltate_on(h, o, 1.0 / wind_lattice(o.wind_from_deg, o.size).cell, w);
}

void saltate(terrain::HeightField& h, const SandOptions& o) {
  Workspace w;
  saltate(h, o, w);
}

void creep(terrain::HeightField& h, double coefficient, int shift) {
  Workspace w;
  creep(h, coefficient, w, shift);
}

void creep(terrain::HeightField& h, double coefficient, Workspace& ws, int shift) {
  const int w = h.width(), rows = h.height();
  ws.next.resize(h.size());
  const float d = static_cast<float>(coefficient / 4.0);
  // Rows past the edges come shifted on the wind lattice (dunes/lattice.h).
  const LatticeRows row(h, shift);
  for_tiles(w, rows, [&](const Tile& t) {
    for (int r = t.first_row; r < t.end_row; ++r) {
      creep_strip(row[r], row[r - 1], row[r + 1], w, t.x0, t.x1, d,
                  &ws.next[static_cast<std::size_t>(r) * w]);
    }
  });
  std::swap(ws.next, h.values());
}

void step(terrain::HeightField& h, const SandOptions& o, Workspace& w) {
  const WindLattice l = wind_lattice(o.wind_from_deg, o.size);
  assert(h.width() == l.columns && h.height() == l.rows);
  saltate_on(h, o, 1.0 / l.cell, w);
  // The paper's D and the repose slope are per grid cell; the lattice's
  // spacing is h cells: D / h^2 and h times the drop per edge.
  creep(h, o.creep / (l.cell * l.cell), w, l.shift);
  // Sweeps with nothing steeper than the limit move nothing (the fluxes are
  // exactly 0), so checking first only saves time: worth it where slopes stay
  // gentle (ripples), not while slip faces are active (dunes).
  const bool check = !w.steep || w.steps % 8 == 0;
  w.steep =
      avalanche(h, max_drop(o) * l.cell, kSweepsPerStep, check ? 1e-4 : -1.0, w.next, l.shift) > 0;
  ++w.steps;
}

void step(terrain::HeightField& h, const SandOptions& o) {
  Workspace w;
  step(h, o, w);
}

terrain::HeightField run(const SandOptions& o, const ProgressFn& progress, int snapshot_every,
                         const SnapshotFn& snapshot) {
  validate(o);
  const WindLattice lattice = wind_lattice(o.wind_from_deg, o.size);
  terrain::HeightField h = initial_field(o);
  Workspace w;
  progress(0.0, "sand");
  for (int s = 0; s < o.steps; ++s) {
    step(h, o, w);
    if (snapshot_every > 0 && snapshot && (s + 1) % snapshot_every == 0) {
      snapshot(s + 1, lattice_to_grid(h, lattice, o.size));
    }
    if ((s + 1) % 8 == 0 && !progress(static_cast<double>(s + 1) / o.steps, "")) {
      throw Cancelled();
    }
  }
  // Relaxed fully where the sand moved, then on the model grid, where the
  // final relaxation holds every slope to the angle of repose between grid
  // neighbours. A turned lattice's steps leave the slip faces of fast dunes
  // steeper than repose (4 sweeps a step); relaxed only after interpolation,
  // on the grid, they settled into stripes along the grid's columns. Once
  // relaxed on the lattice, the grid's relaxation only trims what the
  // lattice's 8 directions allow between them (a few sweeps).
  const double limit = max_drop(o);
  if (o.steps > 0 && lattice.turned()) {
    avalanche(h, limit * lattice.cell, kFinalSweeps, 1e-3 * limit, w.next, lattice.shift);
  }
  if (lattice.turned()) h = lattice_to_grid(h, lattice, o.size);
  if (o.steps > 0) avalanche(h, limit, kFinalSweeps, 1e-3 * limit, w.next);
  progress(1.0, "");
  return h;
}

terrain::HeightField to_ground(const terrain::HeightField& m, const SandOptions& o) {
  terrain::HeightField g = turn_to_ground(m, wind_frame(o.wind_from_deg));
  g.geo() = terrain::local_georeference(o.cell_m);
  const float scale = static_cast<float>(o.height_unit);
  for (float& v : g.values()) v *= scale;
  return g;
}

terrain::HeightField simulate(const SandOptions& o, const ProgressFn& progress) {
  return to_ground(run(o, progress), o);
}

}  // namespace drift::dunes
