#include "dunes/sand_model.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "dunes/avalanche.h"
#include "dunes/height_range.h"
#include "dunes/lattice.h"
#include "dunes/wind_frame.h"
#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/simd.h"

namespace drift::dunes {

namespace {

// Fixed row blocks: the work partition, and so every bit, is independent of
// the thread count.
constexpr int kRowBlock = 16;
// Relaxation sweeps per time step: saltation steepens slopes a little each
// step, and a few sweeps keep them at the angle of repose as the sand moves.
constexpr int kSweepsPerStep = 4;
// At the end, relax fully (to a thousandth of a height unit).
constexpr int kFinalSweeps = 20000;

std::uint64_t mix64(std::uint64_t z) {  // SplitMix64's finaliser
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

void require_range(const char* name, double v, double lo, double hi) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "--%s is %g; it must lie in [%g, %g]", name, v, lo, hi);
    throw Error(buf);
  }
}

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
  return std::tan(o.repose_deg * std::numbers::pi / 180.0) * o.cell_m / o.height_unit;
}

// The shadow line's fall per cell along the wind, in model height units.
double shadow_drop(const SandOptions& o) {
  return std::tan(o.shadow_deg * std::numbers::pi / 180.0) * o.cell_m / o.height_unit;
}

template <class Fn>
void for_rows(int rows, Fn fn) {
  tbb::parallel_for(
      tbb::blocked_range<int>(0, rows, kRowBlock),
      [&](const tbb::blocked_range<int>& r) {
        for (int row = r.begin(); row < r.end(); ++row) fn(row);
      },
      tbb::simple_partitioner());
}

}  // namespace

SandOptions default_options(Model model) {
  SandOptions o;
  o.model = model;
  if (model == Model::Dunes) {
    // Large scale: flights shorten and lift grows on windward slopes.
    o.cell_m = 1.0;
    o.height_unit = 0.25;
    o.L0 = 20.0;
    o.b = 1.0;
    o.q = 0.2;
    o.b_prime = 0.02;
    o.creep = 0.25;
    o.initial_amplitude = 2.0;
    o.steps = 3000;
    o.shadow_deg = 15.0;
    o.reattach = 1.0;
  }
  return o;
}

void validate(const SandOptions& o) {
  require_range("size", o.size, 8, 16384);
  require_range("cell", o.cell_m, 1e-4, 1e3);
  require_range("height-unit", o.height_unit, 1e-6, 1e3);
  require_range("steps", o.steps, 0, 1e7);
  require_range("L0", o.L0, 0.5, 64);
  require_range("b", o.b, 0, 32);
  require_range("q", o.q, 1e-4, 2);
  require_range("b-prime", o.b_prime, 0, 2);
  require_range("creep", o.creep, 0, 1);
  require_range("amplitude", o.initial_amplitude, 0, 1e3);
  require_range("repose", o.repose_deg, 1, 89);
  require_range("wind", o.wind_from_deg, -360, 360);
  require_range("shadow", o.shadow_deg, 0, 89);
  require_range("reattach", o.reattach, 0, 16);
  if (o.model == Model::Dunes) {
    if (o.L0 <= o.b) throw Error("dunes need --L0 > --b, or windward flights go backwards");
    if (o.q <= o.b_prime) throw Error("dunes need --q > --b-prime, or the lift turns negative");
  }
  const std::uint64_t cells = static_cast<std::uint64_t>(o.size) * o.size;
  // Heights, the next field (saltation, creep, avalanching) and the wind
  // shadow on the wind lattice (at most as many points as the grid), then
  // the field on the grid and its next.
  require_memory(cells * (4 + 4 + 2 + 4 + 4), "the sand grid", "choose a smaller --size");
}

terrain::HeightField initial_field(const SandOptions& o) {
  const WindLattice l = wind_lattice(o.wind_from_deg, o.size);
  terrain::HeightField h(l.columns, l.rows, 0.0f, terrain::local_georeference(o.cell_m));
  const std::uint64_t key = mix64(o.seed);
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double u = static_cast<double>(mix64(key ^ mix64(i)) >> 11) * 0x1.0p-53;
    h.values()[i] = static_cast<float>(u * o.initial_amplitude);
  }
  return h;
}

namespace {

// How saltation's landings are summed. The sand lives on the wind lattice
// (dunes/wind_frame.h), whose rows are the wind lines and close on
// themselves, so a flight lands on its own row, past the last column
// wrapped, shared linearly between the two points around the landing (as
// the paper has it along x). Each row's landings are summed in double
// precision in a private window in a fixed order, and each point is rounded
// to float once, so mass is kept to float rounding and the bits do not
// depend on the thread count.
//
// Flight lengths and slopes are in grid cells, as in the paper; the
// lattice's columns are h cells apart: `per_cell` = 1 / h columns a cell.

// The longest flight, in cells, short of a lap of the row.
double max_flight(const terrain::HeightField& h, const SandOptions& o, double per_cell) {
  double longest = o.L0 + o.b;  // dunes: L0 - b tanh(.) <= L0 + b
  if (o.model == Model::Ripples) {
    const float top = height_range(h).hi;
    longest = o.L0 + o.b * top;
  }
  return std::clamp(longest, 0.0, (h.width() - 1.0) / per_cell);
}

// A flight of `flight` cells along the wind in columns (times per_cell),
// kept within a lap (`longest` cells) by selects so that loops over it
// vectorise.
DRIFT_SIMD_KERNEL double columns_along(double flight, double longest, double per_cell) {
  const double positive = flight > 0.0 ? flight : 0.0;
  return (positive < longest ? positive : longest) * per_cell;
}

// Eqs. 2-3 along a row c of the lattice, a wind line: dH/dx is the central
// difference between its neighbours on the line, a column (1 / per_cell
// cells) either side; `before` is the point before the first column and
// `after` the one after the last (the row's last and first). The line's own
// points: the gradient of 4 grid neighbours dotted with the wind would take
// an oblique slope from the neighbouring lines only, blind to the point's own
// (docs/dunes.md).
struct DuneLaunch {
  float per_cell_f;  // columns per cell along the wind
  double L0, b, q, b_prime, longest, per_cell;
};

DRIFT_SIMD_KERNEL void launch_dunes_kernel(const float* __restrict c, int n, float before,
                                           float after, const DuneLaunch& p,
                                           double* __restrict columns, double* __restrict lift) {
  // Parameters as locals: the outputs could alias them otherwise.
  const float per_cell_f = p.per_cell_f;
  const double L0 = p.L0, b = p.b, q = p.q, b_prime = p.b_prime, longest = p.longest;
  const double per_cell = p.per_cell;
  auto fill = [&](int x, float upwind, float downwind) {
    const double g = fast_tanh(per_cell_f * (0.5f * (downwind - upwind)));
    columns[x] = columns_along(L0 - b * g, longest, per_cell);
    lift[x] = q + b_prime * g;
  };
  fill(0, before, c[1]);
  for (int x = 1; x + 1 < n; ++x) fill(x, c[x - 1], c[x + 1]);
  fill(n - 1, c[n - 2], after);
}
DRIFT_SIMD_TWINS(launch_dunes, launch_dunes_kernel,
                 (const float* c, int n, float before, float after, const DuneLaunch& p,
                  double* columns, double* lift),
                 (c, n, before, after, p, columns, lift))

// Paper eq. 1 (ripples) or eqs. 2-3 (dunes) along one row: the flight of each
// point in columns (its length along the wind times per_cell) and its lift.
void launch_row(const terrain::HeightField& h, const SandOptions& o, double per_cell, int row,
                double* __restrict columns, double* __restrict lift) {
  const int n = h.width();
  const float* __restrict c = &h(0, row);
  const double longest = (n - 1.0) / per_cell, L0 = o.L0, b = o.b, q = o.q;
  if (o.model == Model::Ripples) {
    for (int x = 0; x < n; ++x) {
      columns[x] = columns_along(L0 + b * c[x], longest, per_cell);  // L = L0 + b H
      lift[x] = q;
    }
    return;
  }
  const DuneLaunch p{.per_cell_f = static_cast<float>(per_cell),
                     .L0 = L0,
                     .b = b,
                     .q = q,
                     .b_prime = o.b_prime,
                     .longest = longest,
                     .per_cell = per_cell};
  launch_dunes(c, n, c[n - 1], c[0], p, columns, lift);
}

// Where each flight of a row lands in the window: the window index of the
// point left of the landing and of the one right of it, and the sand each
// gets, shared linearly.
struct Landings {
  std::vector<std::int32_t> left, right;
  std::vector<double> to_left, to_right;
};

// Per-row scratch of saltation: each point's flight (columns) and lift, the
// lift's recovery past shadows along the row, and where the flights land.
struct RowScratch {
  std::vector<double> columns, lift;
  std::vector<float> recovery;
  Landings landings;
  void resize(int n) {
    recovery.resize(n);
    for (auto* v : {&columns, &lift, &landings.to_left, &landings.to_right}) v->resize(n);
    landings.left.resize(n);
    landings.right.resize(n);
  }
};

// Where the flights (`reach` columns downwind, carrying `part`) of a row
// land: column x + reach, wrapped onto the row. Branch free, so it
// vectorises; the scattering adds are left to fly().
DRIFT_SIMD_KERNEL void aim_kernel(int n, const double* __restrict reach,
                                  const double* __restrict part, std::int32_t* __restrict left,
                                  std::int32_t* __restrict right, double* __restrict to_left,
                                  double* __restrict to_right) {
  for (int x = 0; x < n; ++x) {
    const double land_x = x + reach[x];
    const int i0 = static_cast<int>(land_x);
    const double fx = land_x - i0;
    const int a = i0 >= n ? i0 - n : i0;
    const int b = a + 1 == n ? 0 : a + 1;
    left[x] = a;
    right[x] = b;
    to_left[x] = part[x] * (1.0 - fx);
    to_right[x] = part[x] * fx;
  }
}
DRIFT_SIMD_TWINS(aim, aim_kernel,
                 (int n, const double* reach, const double* part, std::int32_t* left,
                  std::int32_t* right, double* to_left, double* to_right),
                 (n, reach, part, left, right, to_left, to_right))

// Lifts `part` from each point of the row in `window` and adds it where
// aim() found it lands (a share of 0 on a landing exactly on a point adds
// nothing).
void fly(int n, const double* part, const Landings& l, double* window) {
  for (int x = 0; x < n; ++x) {
    window[x] -= part[x];
    window[l.left[x]] += l.to_left[x];
    window[l.right[x]] += l.to_right[x];
  }
}

// Where a row's sand flies when the lee of crests is out of the wind
// (Werner 1995): sand there is not lifted (times 1 or 0: lifts are >= 0,
// so exact, and unlike a select GCC vectorises it), and grains flying into
// it are caught at its edge. With a recovery (reattach > 0) the lift is
// scaled by it too.
DRIFT_SIMD_KERNEL void shade_kernel(const std::uint16_t* __restrict shadow,
                                    const float* __restrict recovery, int n,
                                    double* __restrict columns, double* __restrict lift) {
  if (recovery) {
    for (int x = 0; x < n; ++x) {
      const int s = shadow[x];
      lift[x] = lift[x] * static_cast<double>(~s & 1) * recovery[x];
      columns[x] = std::min(columns[x], static_cast<double>(s >> 1));
    }
    return;
  }
  for (int x = 0; x < n; ++x) {
    const int s = shadow[x];
    lift[x] *= static_cast<double>(~s & 1);
    columns[x] = std::min(columns[x], static_cast<double>(s >> 1));
  }
}
DRIFT_SIMD_TWINS(shade, shade_kernel,
                 (const std::uint16_t* shadow, const float* recovery, int n, double* columns,
                  double* lift),
                 (shadow, recovery, n, columns, lift))

// What saltation needs to know once per step.
struct SaltationPlan {
  double per_cell = 1.0;  // lattice columns a grid cell along the wind (1 / h)
  const ShadowMap* shadow = nullptr;
  double reattach = 0.0;  // with a shadow: see shadow_recovery()
};

// One row's landings into the window of the row.
// The flights are worked out first, in loops that vectorise, then flown (a
// shadowed part is 0 and adds nothing).
void saltate_row(const terrain::HeightField& h, const SandOptions& o, const SaltationPlan& p,
                 int row, double* window, RowScratch& scratch) {
  const int n = h.width();
  double* columns = scratch.columns.data();
  double* lift = scratch.lift.data();
  launch_row(h, o, p.per_cell, row, columns, lift);
  if (p.shadow) {
    const std::uint16_t* shadow = p.shadow->data() + static_cast<std::size_t>(row) * n;
    const float* recovery = nullptr;
    if (p.reattach > 0.0) {
      line_recovery(shadow, n, p.reattach, scratch.recovery.data());
      recovery = scratch.recovery.data();
    }
    shade(shadow, recovery, n, columns, lift);
  }
  Landings& l = scratch.landings;
  aim(n, columns, lift, l.left.data(), l.right.data(), l.to_left.data(), l.to_right.data());
  fly(n, lift, l, window);
}

// Rows [begin, end), each in turn: its sources' landings summed in a window
// of the row, then each point rounded once into `out`.
void land_rows(const terrain::HeightField& h, const SandOptions& o, const SaltationPlan& p,
               int begin, int end, std::vector<float>& out) {
  const int n = h.width();
  thread_local std::vector<double> window;
  thread_local RowScratch scratch;
  window.resize(static_cast<std::size_t>(n));
  scratch.resize(n);
  for (int r = begin; r < end; ++r) {
    std::copy(&h(0, r), &h(0, r) + n, window.begin());
    saltate_row(h, o, p, r, window.data(), scratch);
    std::copy(window.begin(), window.end(), out.begin() + static_cast<std::ptrdiff_t>(r) * n);
  }
}

// Saltation on a lattice `per_cell` columns a grid cell along the wind.
void saltate_on(terrain::HeightField& h, const SandOptions& o, double per_cell, Workspace& w) {
  const int rows = h.height();
  SaltationPlan p;
  p.per_cell = per_cell;
  if (o.shadow_deg > 0.0) {
    // The shadow is needed as far ahead as the longest flight reaches; its
    // line falls shadow_drop per cell, so per column 1 / per_cell times that.
    const double longest = max_flight(h, o, p.per_cell);
    wind_shadow(h, shadow_drop(o) / p.per_cell, longest * p.per_cell, w.shadow);
    p.shadow = &w.shadow;
    p.reattach = o.reattach;
  }
  w.next.resize(h.size());
  const int blocks = std::max(1, rows / kRowBlock);
  tbb::parallel_for(
      0, blocks,
      [&](int i) {
        const int end = i + 1 == blocks ? rows : (i + 1) * kRowBlock;
        land_rows(h, o, p, i * kRowBlock, end, w.next);
      },
      tbb::simple_partitioner());
  std::swap(w.next, h.values());
}

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
  for_rows(rows, [&](int row) {
    // Rows past the edges come shifted on the wind lattice (dunes/lattice.h).
    thread_local std::vector<float> above, below;
    const float* __restrict c = &h(0, row);
    const float* __restrict n = lattice_row(h, row - 1, shift, above);
    const float* __restrict s = lattice_row(h, row + 1, shift, below);
    float* __restrict out = &ws.next[static_cast<std::size_t>(row) * w];
    // Sum of edge fluxes d * (neighbour - centre): antisymmetric per edge.
    // The wrapped columns apart, so the loop between them vectorises.
    auto cell = [&](int x, int xl, int xr) {
      out[x] = c[x] + d * ((c[xl] - c[x]) + (c[xr] - c[x]) + (n[x] - c[x]) + (s[x] - c[x]));
    };
    cell(0, w - 1, 1);
    for (int x = 1; x + 1 < w; ++x) cell(x, x - 1, x + 1);
    cell(w - 1, w - 2, 0);
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
