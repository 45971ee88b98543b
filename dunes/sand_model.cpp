#include "dunes/sand_model.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "dunes/avalanche.h"
#include "dunes/height_range.h"
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
  // Heights, the double accumulator of saltation, creep's next field, the
  // wind shadow and the lift's recovery past it.
  require_memory(cells * (4 + 8 + 4 + 2 + 4), "the sand grid", "choose a smaller --size");
}

terrain::HeightField initial_field(const SandOptions& o) {
  terrain::HeightField h(o.size, o.size, 0.0f, terrain::local_georeference(o.cell_m));
  const std::uint64_t key = mix64(o.seed);
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double u = static_cast<double>(mix64(key ^ mix64(i)) >> 11) * 0x1.0p-53;
    h.values()[i] = static_cast<float>(u * o.initial_amplitude);
  }
  return h;
}

namespace {

// How saltation's landings are summed. A landing (x + L cos a, y + L sin a)
// is shared among the 4 cells around it, so source row y writes rows y to
// y + spill (t > 0) or y - spill to y (t < 0); spill = 0 for a wind along x.
// Rows are cut into fixed blocks at least `spill` tall. A block sums its
// sources' landings in double precision in a private window of its rows and
// the spill rows beyond them, then writes its rows, except the `spill`
// shared rows that its neighbour's landings reach: those, and its spill
// rows, it keeps (still in double) until a second pass adds each neighbour's
// spill to them. Every sum runs in a fixed order, so the bits do not depend
// on the thread count (a 2-D scatter cannot be cut into independent rows),
// and each cell is rounded to float once, so mass is kept to float rounding.
struct Blocks {
  int spill = 0;      // rows a landing may reach beyond its source row
  int direction = 0;  // +1: landings reach rows below (t > 0); -1: above
  int rows = 0, size = 0, count = 0;
  int begin(int i) const { return i * size; }
  int end(int i) const { return i + 1 == count ? rows : (i + 1) * size; }
  // First row of block i's window (unwrapped) and its row count.
  int window_begin(int i) const { return begin(i) - (direction < 0 ? spill : 0); }
  int window_rows(int i) const { return end(i) - begin(i) + spill; }
  // First of the rows of block i that a neighbour's landings reach, and the
  // first row of the rows block i's landings reach beyond its own.
  int shared_begin(int i) const { return direction > 0 ? begin(i) : end(i) - spill; }
  int spill_begin(int i) const { return direction > 0 ? end(i) : begin(i) - spill; }
  // The block whose spill lands on block i's shared rows.
  int feeder(int i) const { return (i - direction + count) % count; }
};

double max_flight(const terrain::HeightField& h, const SandOptions& o) {
  double longest = o.L0 + o.b;  // dunes: L0 - b tanh(.) <= L0 + b
  if (o.model == Model::Ripples) {
    const float top = height_range(h).hi;
    longest = o.L0 + o.b * top;
  }
  return std::clamp(longest, 0.0, h.width() - 1.0);
}

// `longest`: the longest flight, cells along the wind.
Blocks landing_blocks(const terrain::HeightField& h, double longest, const WindFrame& wind) {
  Blocks b;
  b.rows = h.height();
  const double t = wind.rows_per_column();
  if (t != 0.0) {
    b.spill = static_cast<int>(longest * wind.cos_a * std::fabs(t)) + 1;
    b.direction = t > 0 ? 1 : -1;
  }
  // Blocks twice the spill (or more) keep the kept rows under half the field.
  b.size = b.spill == 0 ? kRowBlock : std::max(2 * kRowBlock, 2 * b.spill);
  b.count = std::max(1, b.rows / b.size);
  if (b.count == 1) b.size = b.rows;
  // One block: its landings wrap onto itself, which needs them to stay
  // within a lap of rows (square grids: flights are under a lap of columns).
  if (b.spill > b.rows) {
    throw Error("an oblique wind needs at least " + std::to_string(b.spill) +
                " rows of sand for its longest flight; the grid has " + std::to_string(b.rows));
  }
  return b;
}

// A flight of `flight` cells along the wind in columns (times cos a), kept
// within a lap (`longest` cells) by selects so that loops over it vectorise.
DRIFT_SIMD_KERNEL double columns_along(double flight, double longest, double cos_a) {
  const double positive = flight > 0.0 ? flight : 0.0;
  return (positive < longest ? positive : longest) * cos_a;
}

// Eqs. 2-3 along a row c: dH/dx is the slope along the wind line through
// each cell, between the points a column up- and downwind on it, (x -+ 1,
// y -+ t), each interpolated between the two rows around it: `ahead` is the
// row the line reaches downwind (below for t > 0), `behind` the one it comes
// from, `t_abs` = |t|. For t = 0 this is the row's central difference; for
// t = +-1 the diagonal's. The gradient of the 4 neighbours dotted with the
// wind would instead take an oblique slope from the neighbouring wind lines
// only, blind to the cell's own (odd-even decoupling): at a wind from 300,
// steep windward faces then covered 45 % as much area as steep lee faces,
// against 17 % with the slope along the line (docs/dunes.md).
struct DuneLaunch {
  float t_abs, cos_a_f;  // cos_a_f: cos a, columns per cell along the wind
  double L0, b, q, b_prime, longest, cos_a;
};

DRIFT_SIMD_KERNEL void launch_dunes_kernel(const float* __restrict c,
                                           const float* __restrict behind,
                                           const float* __restrict ahead, int n,
                                           const DuneLaunch& p, double* __restrict columns,
                                           double* __restrict lift) {
  // Parameters as locals: the outputs could alias them otherwise.
  const float a = p.t_abs, stay = 1.0f - p.t_abs, per_cell = p.cos_a_f;
  const double L0 = p.L0, b = p.b, q = p.q, b_prime = p.b_prime, longest = p.longest;
  const double cos_a = p.cos_a;
  auto fill = [&](int x, int xl, int xr) {
    const float downwind = stay * c[xr] + a * ahead[xr];
    const float upwind = stay * c[xl] + a * behind[xl];
    const double g = fast_tanh(per_cell * (0.5f * (downwind - upwind)));
    columns[x] = columns_along(L0 - b * g, longest, cos_a);
    lift[x] = q + b_prime * g;
  };
  fill(0, n - 1, 1);
  for (int x = 1; x + 1 < n; ++x) fill(x, x - 1, x + 1);
  fill(n - 1, n - 2, 0);
}
DRIFT_SIMD_TWINS(launch_dunes, launch_dunes_kernel,
                 (const float* c, const float* behind, const float* ahead, int n,
                  const DuneLaunch& p, double* columns, double* lift),
                 (c, behind, ahead, n, p, columns, lift))

// Paper eq. 1 (ripples) or eqs. 2-3 (dunes) along one row: the flight of each
// cell in columns (its length along the wind times cos a) and its lift.
void launch_row(const terrain::HeightField& h, const SandOptions& o, const WindFrame& wind, int row,
                double* __restrict columns, double* __restrict lift) {
  const int n = h.width(), rows = h.height();
  const float* __restrict c = &h(0, row);
  const double longest = n - 1.0, cos_a = wind.cos_a, L0 = o.L0, b = o.b, q = o.q;
  if (o.model == Model::Ripples) {
    for (int x = 0; x < n; ++x) {
      columns[x] = columns_along(L0 + b * c[x], longest, cos_a);  // L = L0 + b H
      lift[x] = q;
    }
    return;
  }
  const double t = wind.rows_per_column();
  const DuneLaunch p{.t_abs = static_cast<float>(std::fabs(t)),
                     .cos_a_f = static_cast<float>(wind.cos_a),
                     .L0 = L0,
                     .b = b,
                     .q = q,
                     .b_prime = o.b_prime,
                     .longest = longest,
                     .cos_a = cos_a};
  const float* up = &h(0, row == 0 ? rows - 1 : row - 1);
  const float* down = &h(0, row + 1 == rows ? 0 : row + 1);
  launch_dunes(c, t > 0 ? up : down, t > 0 ? down : up, n, p, columns, lift);
}

// Where each flight of a row lands in the window: the window index of the
// cell left of the landing on its top row and of the one right of it
// (columns wrap), and the sand each of the (up to) 4 cells around the
// landing gets, shared bilinearly (linearly between 2 for a wind along x,
// as the paper has it).
struct Landings {
  std::vector<std::int32_t> left, right;
  std::vector<double> top_left, top_right, bottom_left, bottom_right;
};

// Per-row scratch of saltation: each cell's flight (columns) and lift, for
// an oblique wind with shadows the flight and part along its second wind
// line, and where they land.
struct RowScratch {
  std::vector<double> columns, lift, columns_b, lift_b;
  std::vector<float> recovery;
  Landings landings;
  void resize(int n) {
    recovery.resize(n);
    for (auto* v : {&columns, &lift, &columns_b, &lift_b, &landings.top_left, &landings.top_right,
                    &landings.bottom_left, &landings.bottom_right}) {
      v->resize(n);
    }
    landings.left.resize(n);
    landings.right.resize(n);
  }
};

// Where the flights (`reach` columns downwind, carrying `part`) of the row
// at window row y land: (x + reach, y + reach t), t = 0 for a wind along x
// (kOblique false). Every landing stays inside the window (its rows reach
// the longest flight beyond the block). Branch free, so it vectorises; the
// scattering adds are left to fly().
template <bool kOblique>
DRIFT_SIMD_KERNEL void aim_kernel(int n, int y, double t, const double* __restrict reach,
                                  const double* __restrict part, std::int32_t* __restrict left,
                                  std::int32_t* __restrict right, double* __restrict top_left,
                                  double* __restrict top_right, double* __restrict bottom_left,
                                  double* __restrict bottom_right) {
  for (int x = 0; x < n; ++x) {
    const double land_x = x + reach[x];
    const int i0 = static_cast<int>(land_x);
    const double fx = land_x - i0;
    const int a = i0 >= n ? i0 - n : i0, b = a + 1 == n ? 0 : a + 1;
    int top = y * n;
    double upper = part[x];
    if (kOblique) {
      const double land_y = y + reach[x] * t;
      const int j0 = static_cast<int>(land_y);  // land_y >= 0: truncation floors
      const double fy = land_y - j0;
      top = j0 * n;
      upper = part[x] * (1.0 - fy);
      const double lower = part[x] * fy;
      bottom_left[x] = lower * (1.0 - fx);
      bottom_right[x] = lower * fx;
    }
    left[x] = top + a;
    right[x] = top + b;
    top_left[x] = upper * (1.0 - fx);
    top_right[x] = upper * fx;
  }
}
#define DRIFT_AIM_PARAMS                                                                \
  (int n, int y, double t, const double* reach, const double* part, std::int32_t* left, \
   std::int32_t* right, double* top_left, double* top_right, double* bottom_left,       \
   double* bottom_right)
#define DRIFT_AIM_ARGS \
  (n, y, t, reach, part, left, right, top_left, top_right, bottom_left, bottom_right)
DRIFT_SIMD_TWINS(aim_along_x, aim_kernel<false>, DRIFT_AIM_PARAMS, DRIFT_AIM_ARGS)
DRIFT_SIMD_TWINS(aim_oblique, aim_kernel<true>, DRIFT_AIM_PARAMS, DRIFT_AIM_ARGS)
#undef DRIFT_AIM_PARAMS
#undef DRIFT_AIM_ARGS

template <bool kOblique>
void aim(int n, int y, double t, const double* reach, const double* part, Landings& l) {
  (kOblique ? aim_oblique : aim_along_x)(n, y, t, reach, part, l.left.data(), l.right.data(),
                                         l.top_left.data(), l.top_right.data(),
                                         l.bottom_left.data(), l.bottom_right.data());
}

// Lifts `part` from each cell of the row at window row y and adds it where
// aim() found it lands (a share of 0 on a landing exactly on a row adds
// nothing).
template <bool kOblique>
void fly(int n, int y, const double* part, const Landings& l, double* window) {
  double* source = window + static_cast<std::size_t>(y) * n;
  for (int x = 0; x < n; ++x) {
    source[x] -= part[x];
    window[l.left[x]] += l.top_left[x];
    window[l.right[x]] += l.top_right[x];
    if (kOblique) {
      window[l.left[x] + n] += l.bottom_left[x];
      window[l.right[x] + n] += l.bottom_right[x];
    }
  }
}

// For a wind along x, shade_row's line is the row and the shadow map's row
// (and the recovery's, if not null) is read straight through: a loop that
// vectorises.
DRIFT_SIMD_KERNEL void shade_along_x_kernel(const std::uint16_t* __restrict shadow,
                                            const float* __restrict recovery, int n,
                                            double* __restrict columns, double* __restrict lift) {
  // Times 1 or 0 (lifts are >= 0): exact, and unlike a select GCC
  // vectorises it.
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
DRIFT_SIMD_TWINS(shade_along_x, shade_along_x_kernel,
                 (const std::uint16_t* shadow, const float* recovery, int n, double* columns,
                  double* lift),
                 (shadow, recovery, n, columns, lift))

// Where a row's sand flies when the lee of crests is out of the wind
// (Werner 1995): sand there is not lifted, and grains flying into it are
// caught at its edge. A cell's sand follows the two wind lines around it in
// proportion (one line, its row, for a wind along x): on entry `lift` and
// `columns` hold the cell's lift and flight; on return the part that flies
// along the first line and how far it gets, and in `lift_b`, `columns_b`
// the same for the second (kOblique only).
//
// With `reattach` > 0 the lift recovers past a shadow's end
// (shadow_recovery()): along x worked out here for the row, into
// `row_recovery` (a row that stays in cache, not a map through memory);
// obliquely read from `recovery`, which wind_shadow() filled.
template <bool kOblique>
void shade_row(const ShadowMap& shadow, double reattach, const std::vector<float>* recovery,
               const Crossing* crossings, int n, int row, int rows, double* __restrict columns,
               double* __restrict lift, double* __restrict columns_b, double* __restrict lift_b,
               float* row_recovery) {
  if (!kOblique) {
    const std::uint16_t* line = &shadow[static_cast<std::size_t>(row) * n];
    if (reattach > 0.0) line_recovery(line, n, reattach, row_recovery);
    shade_along_x(line, reattach > 0.0 ? row_recovery : nullptr, n, columns, lift);
    return;
  }
  for (int x = 0; x < n; ++x) {
    const CellLines lines = cell_lines(crossings[x], row, rows);
    const double flight = columns[x], sand = lift[x];
    const std::size_t at_a = static_cast<std::size_t>(lines.line_a) * n + x;
    const std::size_t at_b = static_cast<std::size_t>(lines.line_b) * n + x;
    const int s_a = shadow[at_a], s_b = shadow[at_b];
    const double r_a = recovery ? (*recovery)[at_a] : 1.0;
    const double r_b = recovery ? (*recovery)[at_b] : 1.0;
    // Times 1 or 0, as in shade_along_x: no branches on the relief.
    lift[x] = sand * lines.weight_a * static_cast<double>(~s_a & 1) * r_a;
    columns[x] = std::min(flight, static_cast<double>(s_a >> 1));
    lift_b[x] = sand * (1.0 - lines.weight_a) * static_cast<double>(~s_b & 1) * r_b;
    columns_b[x] = std::min(flight, static_cast<double>(s_b >> 1));
  }
}

// What saltation needs to know once per step.
struct SaltationPlan {
  WindFrame wind;
  Blocks blocks;
  // Oblique winds with a shadow: per column, rows modulo the field's.
  std::vector<Crossing> crossings;
  const ShadowMap* shadow = nullptr;
  double reattach = 0.0;                         // with a shadow: see shadow_recovery()
  const std::vector<float>* recovery = nullptr;  // oblique winds: worked out by wind_shadow()
  std::size_t kept_rows = 0;                     // per block: its shared rows, then its spill rows
};

// One source row's landings into the window (`y`: the row's place in it).
// Compiled twice: kOblique false drops the sideways arithmetic of a wind
// along x (a third of the work of a ripple step), nothing else. The flights
// are worked out first, in loops that vectorise, then flown (a shadowed part
// is 0 and adds nothing).
template <bool kOblique>
void saltate_row(const terrain::HeightField& h, const SandOptions& o, const SaltationPlan& p,
                 int row, int y, double* window, RowScratch& scratch) {
  const int n = h.width();
  const double t = p.wind.rows_per_column();
  double* columns = scratch.columns.data();
  double* lift = scratch.lift.data();
  launch_row(h, o, p.wind, row, columns, lift);
  const bool two_lines = kOblique && p.shadow;
  if (p.shadow) {
    shade_row<kOblique>(*p.shadow, p.reattach, p.recovery, p.crossings.data(), n, row, h.height(),
                        columns, lift, scratch.columns_b.data(), scratch.lift_b.data(),
                        scratch.recovery.data());
  }
  auto flights = [&](const double* reach, const double* part) {
    aim<kOblique>(n, y, t, reach, part, scratch.landings);
    fly<kOblique>(n, y, part, scratch.landings, window);
  };
  flights(columns, lift);
  if (two_lines) flights(scratch.columns_b.data(), scratch.lift_b.data());
}

// Block i: its sources' landings summed in its window; rows nobody else
// reaches go to `out` (rounded once), shared and spill rows to `kept`.
void land_block(const terrain::HeightField& h, const SandOptions& o, const SaltationPlan& p, int i,
                double* kept, std::vector<float>& out) {
  const int n = h.width();
  const Blocks& b = p.blocks;
  thread_local std::vector<double> window;
  thread_local RowScratch scratch;
  const int wb = b.window_begin(i), wrows = b.window_rows(i);
  window.resize(static_cast<std::size_t>(wrows) * n);
  scratch.resize(n);
  // Own rows start from the heights, spill rows from 0.
  for (int r = b.begin(i); r < b.end(i); ++r)
    std::copy(&h(0, r), &h(0, r) + n, window.begin() + static_cast<std::size_t>(r - wb) * n);
  const int spill_row = b.direction > 0 ? b.end(i) - wb : 0;
  std::fill_n(window.begin() + static_cast<std::size_t>(spill_row) * n,
              static_cast<std::size_t>(b.spill) * n, 0.0);
  const bool oblique = p.wind.rows_per_column() != 0.0;
  for (int r = b.begin(i); r < b.end(i); ++r) {
    (oblique ? saltate_row<true> : saltate_row<false>)(h, o, p, r, r - wb, window.data(), scratch);
  }
  for (int r = wb; r < wb + wrows; ++r) {
    const double* from = window.data() + static_cast<std::size_t>(r - wb) * n;
    const int shared = r - b.shared_begin(i), spilled = r - b.spill_begin(i);
    if (shared >= 0 && shared < b.spill) {
      std::copy(from, from + n, kept + static_cast<std::size_t>(shared) * n);
    } else if (spilled >= 0 && spilled < b.spill) {
      std::copy(from, from + n, kept + static_cast<std::size_t>(b.spill + spilled) * n);
    } else {
      float* to = &out[static_cast<std::size_t>(r) * n];
      for (int x = 0; x < n; ++x) to[x] = static_cast<float>(from[x]);
    }
  }
}

// Block i's shared rows plus the spill its feeder landed on them, rounded once.
void merge_shared_rows(int n, const SaltationPlan& p, int i, const std::vector<double>& kept,
                       std::vector<float>& out) {
  const Blocks& b = p.blocks;
  const double* own = kept.data() + p.kept_rows * n * i;
  const double* fed =
      kept.data() + p.kept_rows * n * b.feeder(i) + static_cast<std::size_t>(b.spill) * n;
  for (int s = 0; s < b.spill; ++s) {
    const int row = (b.shared_begin(i) + s + b.rows) % b.rows;
    float* to = &out[static_cast<std::size_t>(row) * n];
    const std::size_t at = static_cast<std::size_t>(s) * n;
    for (int x = 0; x < n; ++x) to[x] = static_cast<float>(own[at + x] + fed[at + x]);
  }
}

}  // namespace

void saltate(terrain::HeightField& h, const SandOptions& o, Workspace& w) {
  const int n = h.width();
  SaltationPlan p;
  p.wind = wind_frame(o.wind_from_deg);
  const double t = p.wind.rows_per_column();
  const bool shadows = o.shadow_deg > 0.0;
  // The longest flight bounds how far landings reach sideways and how far
  // ahead the shadow must be known (neither matters for a plain wind along x).
  const double longest = t != 0.0 || shadows ? max_flight(h, o) : 0.0;
  if (shadows) {
    // The recovery along oblique lines comes with the shadow (a line's
    // start needs the line arriving across the periodic edge); rows work
    // theirs out as they are shaded.
    const bool map_recovery = o.reattach > 0.0 && t != 0.0;
    wind_shadow(h, t, shadow_drop(o), longest * p.wind.cos_a, w.shadow, o.reattach,
                map_recovery ? &w.recovery : nullptr);
    p.shadow = &w.shadow;
    p.reattach = o.reattach;
    if (map_recovery) p.recovery = &w.recovery;
    // Only oblique lines need to know where they cross each column (rows
    // are their own lines).
    if (t != 0.0) {
      p.crossings.resize(n);
      for (int x = 0; x < n; ++x) {
        p.crossings[x] = crossing(t, x);
        p.crossings[x].row = (p.crossings[x].row % h.height() + h.height()) % h.height();
      }
    }
  }
  p.blocks = landing_blocks(h, longest, p.wind);
  p.kept_rows = 2 * static_cast<std::size_t>(p.blocks.spill);
  w.kept.resize(p.kept_rows * n * p.blocks.count);
  w.next.resize(h.size());
  tbb::parallel_for(
      0, p.blocks.count,
      [&](int i) { land_block(h, o, p, i, w.kept.data() + p.kept_rows * n * i, w.next); },
      tbb::simple_partitioner());
  if (p.blocks.spill > 0) {
    tbb::parallel_for(
        0, p.blocks.count, [&](int i) { merge_shared_rows(n, p, i, w.kept, w.next); },
        tbb::simple_partitioner());
  }
  std::swap(w.next, h.values());
}

void saltate(terrain::HeightField& h, const SandOptions& o) {
  Workspace w;
  saltate(h, o, w);
}

void creep(terrain::HeightField& h, double coefficient) {
  Workspace w;
  creep(h, coefficient, w);
}

void creep(terrain::HeightField& h, double coefficient, Workspace& ws) {
  const int w = h.width(), rows = h.height();
  ws.next.resize(h.size());
  const float d = static_cast<float>(coefficient / 4.0);
  for_rows(rows, [&](int row) {
    const float* __restrict c = &h(0, row);
    const float* __restrict n = &h(0, row == 0 ? rows - 1 : row - 1);
    const float* __restrict s = &h(0, row + 1 == rows ? 0 : row + 1);
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
  saltate(h, o, w);
  creep(h, o.creep, w);
  // Sweeps with nothing steeper than the limit move nothing (the fluxes are
  // exactly 0), so checking first only saves time: worth it where slopes stay
  // gentle (ripples), not while slip faces are active (dunes).
  const bool check = !w.steep || w.steps % 8 == 0;
  w.steep = avalanche(h, max_drop(o), kSweepsPerStep, check ? 1e-4 : -1.0, w.next) > 0;
  ++w.steps;
}

void step(terrain::HeightField& h, const SandOptions& o) {
  Workspace w;
  step(h, o, w);
}

terrain::HeightField run(const SandOptions& o, const ProgressFn& progress, int snapshot_every,
                         const SnapshotFn& snapshot) {
  validate(o);
  terrain::HeightField h = initial_field(o);
  Workspace w;
  progress(0.0, "sand");
  for (int s = 0; s < o.steps; ++s) {
    step(h, o, w);
    if (snapshot_every > 0 && snapshot && (s + 1) % snapshot_every == 0) snapshot(s + 1, h);
    if ((s + 1) % 8 == 0 && !progress(static_cast<double>(s + 1) / o.steps, "")) {
      throw Cancelled();
    }
  }
  if (o.steps > 0) avalanche(h, max_drop(o), kFinalSweeps, 1e-3 * max_drop(o), w.next);
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
