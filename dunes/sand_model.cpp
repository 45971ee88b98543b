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
  // Heights, the next field (saltation, creep, avalanching), the wind
  // shadow, the lift's recovery past it, saltation's columns kept in double
  // (at most two per point, for the longest flights on a sheared lattice)
  // and the field turned from the lattice onto the grid.
  require_memory(cells * (4 + 4 + 2 + 4 + 16 + 4), "the sand grid", "choose a smaller --size");
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

// How saltation's landings are summed. The sand lives on the wind lattice
// (dunes/wind_frame.h), whose rows are the wind lines, so a flight lands on
// its own row, shared linearly between the two points around the landing
// (as the paper has it along x). Rows are cut into fixed blocks; a block sums
// its rows' landings in double precision in a private window, and each point
// is rounded to float once, so mass is kept to float rounding and the bits
// do not depend on the thread count. Along x a flight past the last column
// wraps onto its row. On a sheared lattice it lands on the row a lap on
// (row + shear): the window's rows run `wrap_columns` past the last column,
// and those columns, with the first `wrap_columns` of every row that they
// feed, are kept in double until a second pass adds them up in a fixed order.

double max_flight(const terrain::HeightField& h, const SandOptions& o) {
  double longest = o.L0 + o.b;  // dunes: L0 - b tanh(.) <= L0 + b
  if (o.model == Model::Ripples) {
    const float top = height_range(h).hi;
    longest = o.L0 + o.b * top;
  }
  return std::clamp(longest, 0.0, h.width() - 1.0);
}

// A flight of `flight` cells along the wind in columns (times cos a), kept
// within a lap (`longest` cells) by selects so that loops over it vectorise.
DRIFT_SIMD_KERNEL double columns_along(double flight, double longest, double cos_a) {
  const double positive = flight > 0.0 ? flight : 0.0;
  return (positive < longest ? positive : longest) * cos_a;
}

// Eqs. 2-3 along a row c of the lattice, a wind line: dH/dx is the central
// difference between its neighbours on the line, a column step (1 / cos a
// cells) either side; `before` is the point before the first column and
// `after` the one after the last (across the periodic edge: on a sheared
// lattice a lap of rows back and on). The line's own points: the gradient of
// 4 grid neighbours dotted with the wind would take an oblique slope from
// the neighbouring lines only, blind to the point's own (docs/dunes.md).
struct DuneLaunch {
  float cos_a_f;  // cos a: columns per cell along the wind
  double L0, b, q, b_prime, longest, cos_a;
};

DRIFT_SIMD_KERNEL void launch_dunes_kernel(const float* __restrict c, int n, float before,
                                           float after, const DuneLaunch& p,
                                           double* __restrict columns, double* __restrict lift) {
  // Parameters as locals: the outputs could alias them otherwise.
  const float per_cell = p.cos_a_f;
  const double L0 = p.L0, b = p.b, q = p.q, b_prime = p.b_prime, longest = p.longest;
  const double cos_a = p.cos_a;
  auto fill = [&](int x, float upwind, float downwind) {
    const double g = fast_tanh(per_cell * (0.5f * (downwind - upwind)));
    columns[x] = columns_along(L0 - b * g, longest, cos_a);
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
// point in columns (its length along the wind times cos a) and its lift.
void launch_row(const terrain::HeightField& h, const SandOptions& o, const WindFrame& wind, int row,
                double* __restrict columns, double* __restrict lift) {
  const int n = h.width();
  const float* __restrict c = &h(0, row);
  const double longest = n - 1.0, cos_a = wind.cos_a, L0 = o.L0, b = o.b, q = o.q;
  if (o.model == Model::Ripples) {
    for (int x = 0; x < n; ++x) {
      columns[x] = columns_along(L0 + b * c[x], longest, cos_a);  // L = L0 + b H
      lift[x] = q;
    }
    return;
  }
  const DuneLaunch p{.cos_a_f = static_cast<float>(wind.cos_a),
                     .L0 = L0,
                     .b = b,
                     .q = q,
                     .b_prime = o.b_prime,
                     .longest = longest,
                     .cos_a = cos_a};
  launch_dunes(c, n, lattice_at(h, -1, row, wind.shear), lattice_at(h, n, row, wind.shear), p,
               columns, lift);
}

// Where each flight of a row lands in the window: the window index of the
// point left of the landing and of the one right of it, and the sand each
// gets, shared linearly.
struct Landings {
  std::vector<std::int32_t> left, right;
  std::vector<double> to_left, to_right;
};

// Per-row scratch of saltation: each point's flight (columns) and lift, the
// lift's recovery past shadows along x, and where the flights land.
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

// Where the flights (`reach` columns downwind, carrying `part`) of the row
// at window row y (`stride` values a row) land: column x + reach, wrapped
// onto the row along x (kPastEdge false), or in the window's columns past
// the last on a sheared lattice. Branch free, so it vectorises; the
// scattering adds are left to fly().
template <bool kPastEdge>
DRIFT_SIMD_KERNEL void aim_kernel(int n, int stride, int y, const double* __restrict reach,
                                  const double* __restrict part, std::int32_t* __restrict left,
                                  std::int32_t* __restrict right, double* __restrict to_left,
                                  double* __restrict to_right) {
  const int first = y * stride;
  for (int x = 0; x < n; ++x) {
    const double land_x = x + reach[x];
    const int i0 = static_cast<int>(land_x);
    const double fx = land_x - i0;
    int a = i0, b = i0 + 1;
    if (!kPastEdge) {
      a = i0 >= n ? i0 - n : i0;
      b = a + 1 == n ? 0 : a + 1;
    }
    left[x] = first + a;
    right[x] = first + b;
    to_left[x] = part[x] * (1.0 - fx);
    to_right[x] = part[x] * fx;
  }
}
#define DRIFT_AIM_PARAMS                                                                  \
  (int n, int stride, int y, const double* reach, const double* part, std::int32_t* left, \
   std::int32_t* right, double* to_left, double* to_right)
#define DRIFT_AIM_ARGS (n, stride, y, reach, part, left, right, to_left, to_right)
DRIFT_SIMD_TWINS(aim_wrapping, aim_kernel<false>, DRIFT_AIM_PARAMS, DRIFT_AIM_ARGS)
DRIFT_SIMD_TWINS(aim_past_edge, aim_kernel<true>, DRIFT_AIM_PARAMS, DRIFT_AIM_ARGS)
#undef DRIFT_AIM_PARAMS
#undef DRIFT_AIM_ARGS

// Lifts `part` from each point of the row at window row y and adds it where
// aim() found it lands (a share of 0 on a landing exactly on a point adds
// nothing).
void fly(int n, int stride, int y, const double* part, const Landings& l, double* window) {
  double* source = window + static_cast<std::size_t>(y) * stride;
  for (int x = 0; x < n; ++x) {
    source[x] -= part[x];
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
  WindFrame wind;        // wind_frame(azimuth, n): the lattice's shear
  int wrap_columns = 0;  // sheared lattice: columns past the last a flight may reach
  const ShadowMap* shadow = nullptr;
  double reattach = 0.0;  // with a shadow: see shadow_recovery()
  // Sheared lattice with a recovery: worked out by wind_shadow() (its lines
  // do not close on themselves); along x each row works its own out as it
  // is shaded (a row that stays in cache, not a map through memory).
  const std::vector<float>* recovery = nullptr;
  int stride(int n) const { return n + wrap_columns; }
};

// One source row's landings into the window (`y`: the row's place in it).
// The flights are worked out first, in loops that vectorise, then flown (a
// shadowed part is 0 and adds nothing).
void saltate_row(const terrain::HeightField& h, const SandOptions& o, const SaltationPlan& p,
                 int row, int y, double* window, RowScratch& scratch) {
  const int n = h.width();
  double* columns = scratch.columns.data();
  double* lift = scratch.lift.data();
  launch_row(h, o, p.wind, row, columns, lift);
  if (p.shadow) {
    const std::size_t at = static_cast<std::size_t>(row) * n;
    const float* recovery = nullptr;
    if (p.recovery) {
      recovery = p.recovery->data() + at;
    } else if (p.reattach > 0.0) {
      line_recovery(p.shadow->data() + at, n, p.reattach, scratch.recovery.data());
      recovery = scratch.recovery.data();
    }
    shade(p.shadow->data() + at, recovery, n, columns, lift);
  }
  Landings& l = scratch.landings;
  (p.wrap_columns > 0 ? aim_past_edge : aim_wrapping)(n, p.stride(n), y, columns, lift,
                                                      l.left.data(), l.right.data(),
                                                      l.to_left.data(), l.to_right.data());
  fly(n, p.stride(n), y, lift, l, window);
}

// Rows [begin, end): their sources' landings summed in a window; what
// nobody else reaches goes to `out` (rounded once); on a sheared lattice
// each row's first and past-the-edge `wrap_columns` go to `kept`, per row
// first the one then the other.
void land_rows(const terrain::HeightField& h, const SandOptions& o, const SaltationPlan& p,
               int begin, int end, std::vector<double>& kept, std::vector<float>& out) {
  const int n = h.width(), stride = p.stride(n), wrap = p.wrap_columns;
  thread_local std::vector<double> window;
  thread_local RowScratch scratch;
  window.resize(static_cast<std::size_t>(end - begin) * stride);
  scratch.resize(n);
  for (int r = begin; r < end; ++r) {
    double* row = window.data() + static_cast<std::size_t>(r - begin) * stride;
    std::copy(&h(0, r), &h(0, r) + n, row);
    std::fill(row + n, row + stride, 0.0);
  }
  for (int r = begin; r < end; ++r) saltate_row(h, o, p, r, r - begin, window.data(), scratch);
  for (int r = begin; r < end; ++r) {
    const double* from = window.data() + static_cast<std::size_t>(r - begin) * stride;
    float* to = &out[static_cast<std::size_t>(r) * n];
    for (int x = wrap; x < n; ++x) to[x] = static_cast<float>(from[x]);
    if (wrap > 0) {
      double* keep = kept.data() + static_cast<std::size_t>(r) * 2 * wrap;
      std::copy(from, from + wrap, keep);
      std::copy(from + n, from + n + wrap, keep + wrap);
    }
  }
}

// Row r's first `wrap_columns` plus what flew past the edge of row
// r - shear onto them, rounded once.
void merge_wrapped(int n, const SaltationPlan& p, int r, const std::vector<double>& kept,
                   std::vector<float>& out) {
  const int wrap = p.wrap_columns;
  const int from_row = wrap_index(r - p.wind.shear, n);
  const double* own = kept.data() + static_cast<std::size_t>(r) * 2 * wrap;
  const double* fed = kept.data() + static_cast<std::size_t>(from_row) * 2 * wrap + wrap;
  float* to = &out[static_cast<std::size_t>(r) * n];
  for (int x = 0; x < wrap; ++x) to[x] = static_cast<float>(own[x] + fed[x]);
}

}  // namespace

void saltate(terrain::HeightField& h, const SandOptions& o, Workspace& w) {
  const int n = h.width(), rows = h.height();
  SaltationPlan p;
  p.wind = wind_frame(o.wind_from_deg, n);
  const int shear = p.wind.shear;
  const bool shadows = o.shadow_deg > 0.0;
  // The longest flight bounds how far flights reach past the last column
  // and how far ahead the shadow must be known (neither matters for a plain
  // wind along x).
  const double longest = shear != 0 || shadows ? max_flight(h, o) : 0.0;
  if (shadows) {
    // The recovery along sheared lines comes with the shadow (a line's
    // start needs the line arriving across the periodic edge); rows work
    // theirs out as they are shaded.
    const bool map_recovery = o.reattach > 0.0 && shear != 0;
    wind_shadow(h, shear, shadow_drop(o), longest * p.wind.cos_a, w.shadow, o.reattach,
                map_recovery ? &w.recovery : nullptr);
    p.shadow = &w.shadow;
    p.reattach = o.reattach;
    if (map_recovery) p.recovery = &w.recovery;
  }
  if (shear != 0) {
    // Landings reach at most the flight's columns past the last, plus the
    // right-hand point of their pair.
    p.wrap_columns = std::min(n, static_cast<int>(longest * p.wind.cos_a) + 2);
    w.kept.resize(static_cast<std::size_t>(rows) * 2 * p.wrap_columns);
  }
  w.next.resize(h.size());
  const int blocks = std::max(1, rows / kRowBlock);
  tbb::parallel_for(
      0, blocks,
      [&](int i) {
        const int end = i + 1 == blocks ? rows : (i + 1) * kRowBlock;
        land_rows(h, o, p, i * kRowBlock, end, w.kept, w.next);
      },
      tbb::simple_partitioner());
  if (p.wrap_columns > 0) for_rows(rows, [&](int r) { merge_wrapped(n, p, r, w.kept, w.next); });
  std::swap(w.next, h.values());
}

void saltate(terrain::HeightField& h, const SandOptions& o) {
  Workspace w;
  saltate(h, o, w);
}

void creep(terrain::HeightField& h, double coefficient, int shear) {
  Workspace w;
  creep(h, coefficient, w, shear);
}

namespace {

// Creep on a sheared wind lattice (shear != 0): the paper's diffusion
// D/4 * (sum of neighbours - 4 H) must stay isotropic on the model grid,
// where lattice point (x, r) sits at (x, r + t x). Edges e with weights w_e
// whose sum of w_e e e^T is the identity give, on any smooth field, the
// grid's Laplacian (Taylor: f(p + e) + f(p - e) - 2 f(p) = e^T H e): for
// 0 < t <= 1, e = (1, t) along the line with 1 - t, (0, 1) across with
// 1 - t (1 - t), and (1, t - 1) (the lattice's north-east diagonal) with t;
// mirrored for t < 0. For t = 1 those are the grid's 4 neighbours.
struct CreepWeights {
  float along, across, diagonal;
};

CreepWeights creep_weights(double t) {
  const double a = std::fabs(t);
  return {static_cast<float>(1.0 - a), static_cast<float>(1.0 - a * (1.0 - a)),
          static_cast<float>(a)};
}

// One point: its 3 x 3 neighbourhood given as the row above (n), its row (c)
// and the row below (s) around column x; `rising`: t > 0, whose diagonal
// runs from the south-west to the north-east.
DRIFT_SIMD_KERNEL float creep_point(const float* n, const float* c, const float* s, int x, float d,
                                    const CreepWeights& w, bool rising) {
  const float h = c[x];
  const float d1 = rising ? n[x + 1] : s[x + 1], d2 = rising ? s[x - 1] : n[x - 1];
  return h + d * (w.along * ((c[x - 1] - h) + (c[x + 1] - h)) +
                  w.across * ((n[x] - h) + (s[x] - h)) + w.diagonal * ((d1 - h) + (d2 - h)));
}

DRIFT_SIMD_KERNEL void creep_sheared_kernel(const float* __restrict n, const float* __restrict c,
                                            const float* __restrict s, int w, float d,
                                            const CreepWeights& weights, bool rising,
                                            float* __restrict out) {
  for (int x = 1; x + 1 < w; ++x) out[x] = creep_point(n, c, s, x, d, weights, rising);
}
DRIFT_SIMD_TWINS(creep_sheared, creep_sheared_kernel,
                 (const float* n, const float* c, const float* s, int w, float d,
                  const CreepWeights& weights, bool rising, float* out),
                 (n, c, s, w, d, weights, rising, out))

}  // namespace

void creep(terrain::HeightField& h, double coefficient, Workspace& ws, int shear) {
  const int w = h.width(), rows = h.height();
  ws.next.resize(h.size());
  const float d = static_cast<float>(coefficient / 4.0);
  if (shear != 0) {
    const CreepWeights weights = creep_weights(static_cast<double>(shear) / w);
    for_rows(rows, [&](int row) {
      float* out = &ws.next[static_cast<std::size_t>(row) * w];
      creep_sheared(&h(0, row == 0 ? rows - 1 : row - 1), &h(0, row),
                    &h(0, row + 1 == rows ? 0 : row + 1), w, d, weights, shear > 0, out);
      for (const int x : {0, w - 1}) {
        const Neighbourhood nb = neighbourhood(h, x, row, shear);
        out[x] = creep_point(nb[0].data(), nb[1].data(), nb[2].data(), 1, d, weights, shear > 0);
      }
    });
    std::swap(ws.next, h.values());
    return;
  }
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
  const int shear = wind_frame(o.wind_from_deg, h.width()).shear;
  saltate(h, o, w);
  creep(h, o.creep, w, shear);
  // Sweeps with nothing steeper than the limit move nothing (the fluxes are
  // exactly 0), so checking first only saves time: worth it where slopes stay
  // gentle (ripples), not while slip faces are active (dunes).
  const bool check = !w.steep || w.steps % 8 == 0;
  w.steep = avalanche(h, max_drop(o), kSweepsPerStep, check ? 1e-4 : -1.0, w.next, shear) > 0;
  ++w.steps;
}

void step(terrain::HeightField& h, const SandOptions& o) {
  Workspace w;
  step(h, o, w);
}

terrain::HeightField run(const SandOptions& o, const ProgressFn& progress, int snapshot_every,
                         const SnapshotFn& snapshot) {
  validate(o);
  const int shear = wind_frame(o.wind_from_deg, o.size).shear;
  terrain::HeightField h = initial_field(o);
  Workspace w;
  progress(0.0, "sand");
  for (int s = 0; s < o.steps; ++s) {
    step(h, o, w);
    if (snapshot_every > 0 && snapshot && (s + 1) % snapshot_every == 0) {
      if (shear == 0) {
        snapshot(s + 1, h);
      } else {
        snapshot(s + 1, unshear(h, shear));
      }
    }
    if ((s + 1) % 8 == 0 && !progress(static_cast<double>(s + 1) / o.steps, "")) {
      throw Cancelled();
    }
  }
  // From the wind lattice to the model grid, where the final relaxation
  // holds every slope to the angle of repose between grid neighbours.
  if (shear != 0) h = unshear(h, shear);
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
