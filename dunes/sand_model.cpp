#include "dunes/sand_model.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "dunes/avalanche.h"
#include "terrain/error.h"
#include "terrain/memory.h"

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
// a third of the time of libm's tanhf, and the same bits everywhere.
float fast_tanh(float x) {
  if (x > 4.97f) return 1.0f;
  if (x < -4.97f) return -1.0f;
  const float x2 = x * x;
  const float p = x * (135135.0f + x2 * (17325.0f + x2 * (378.0f + x2)));
  const float q = 135135.0f + x2 * (62370.0f + x2 * (3150.0f + x2 * 28.0f));
  return p / q;
}

// The largest edge drop avalanching allows, in model height units.
double max_drop(const SandOptions& o) {
  return std::tan(o.repose_deg * std::numbers::pi / 180.0) * o.cell_m / o.height_unit;
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
  if (o.model == Model::Dunes) {
    if (o.L0 <= o.b) throw Error("dunes need --L0 > --b, or windward flights go backwards");
    if (o.q <= o.b_prime) throw Error("dunes need --q > --b-prime, or the lift turns negative");
  }
  const std::uint64_t cells = static_cast<std::uint64_t>(o.size) * o.size;
  require_memory(cells * (4 + 4 + 4), "the sand grid", "choose a smaller --size");
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

// The wind shadow of one row (wind along +x): every cell casts a line falling
// `drop_per_cell` per cell downwind, and a cell below the line of the cells
// upwind of it is shadowed. Two passes round the periodic row settle it.
// `next_shadowed[x]` is the first shadowed cell after x, unwrapped (x + n if
// none within a lap).
void wind_shadow(const float* line, int n, double drop_per_cell, std::vector<char>& shadowed,
                 std::vector<int>& next_shadowed) {
  shadowed.assign(n, 0);
  double carried = -1e300;
  for (int pass = 0; pass < 2; ++pass) {
    for (int x = 0; x < n; ++x) {
      carried -= drop_per_cell;
      shadowed[x] = line[x] < carried;
      carried = std::max(carried, static_cast<double>(line[x]));
    }
  }
  next_shadowed.assign(n, 0);
  int next = 2 * n;  // sentinel: no shadow seen yet
  for (int pass = 0; pass < 2; ++pass) {
    for (int x = n - 1; x >= 0; --x) {
      const int at = x + (pass == 0 ? n : 0);
      next_shadowed[x] = next;
      if (shadowed[x]) next = at;
    }
  }
  for (int x = 0; x < n; ++x) next_shadowed[x] = std::min(next_shadowed[x], x + n);
}

void saltate(terrain::HeightField& h, const SandOptions& o) {
  const int n = h.width();
  const double max_flight = n - 1.0;
  const bool shadows = o.shadow_deg > 0.0;
  const double shadow_drop =
      std::tan(o.shadow_deg * std::numbers::pi / 180.0) * o.cell_m / o.height_unit;
  for_rows(h.height(), [&](int row) {
    float* line = &h(0, row);
    // Per-row double accumulator (thread-local scratch).
    thread_local std::vector<double> acc;
    thread_local std::vector<int> next_shadowed;
    thread_local std::vector<char> shadowed;
    acc.assign(line, line + n);
    if (shadows) wind_shadow(line, n, shadow_drop, shadowed, next_shadowed);
    for (int x = 0; x < n; ++x) {
      double flight, lift;
      if (o.model == Model::Ripples) {
        flight = o.L0 + o.b * line[x];  // paper eq. 1: L = L0 + b H
        lift = o.q;
      } else {
        // Paper eqs. 2-3 with the central slope along the wind.
        const int xl = x == 0 ? n - 1 : x - 1, xr = x + 1 == n ? 0 : x + 1;
        const double g = fast_tanh(0.5f * (line[xr] - line[xl]));
        flight = o.L0 - o.b * g;
        lift = o.q + o.b_prime * g;
      }
      flight = std::clamp(flight, 0.0, max_flight);
      double land = x + flight;
      if (shadows) {
        // Werner (1995): the lee of a crest is out of the wind. Sand there is
        // not lifted, and grains flying into it are caught at its edge.
        if (shadowed[x]) lift = 0.0;
        land = std::min(land, static_cast<double>(next_shadowed[x]));
      }
      const int i0 = static_cast<int>(land);
      const double frac = land - i0;
      const int a = i0 >= n ? i0 - n : i0;
      const int b = a + 1 >= n ? a + 1 - n : a + 1;
      acc[x] -= lift;
      acc[a] += lift * (1.0 - frac);
      acc[b] += lift * frac;
    }
    for (int x = 0; x < n; ++x) line[x] = static_cast<float>(acc[x]);
  });
}

void creep(terrain::HeightField& h, double coefficient) {
  const int w = h.width(), rows = h.height();
  std::vector<float> next(h.size());
  const float d = static_cast<float>(coefficient / 4.0);
  for_rows(rows, [&](int row) {
    const float* c = &h(0, row);
    const float* n = &h(0, row == 0 ? rows - 1 : row - 1);
    const float* s = &h(0, row + 1 == rows ? 0 : row + 1);
    float* out = &next[static_cast<std::size_t>(row) * w];
    for (int x = 0; x < w; ++x) {
      const int xl = x == 0 ? w - 1 : x - 1, xr = x + 1 == w ? 0 : x + 1;
      // Sum of edge fluxes d * (neighbour - centre): antisymmetric per edge.
      out[x] = c[x] + d * ((c[xl] - c[x]) + (c[xr] - c[x]) + (n[x] - c[x]) + (s[x] - c[x]));
    }
  });
  std::swap(next, h.values());
}

void step(terrain::HeightField& h, const SandOptions& o) {
  saltate(h, o);
  creep(h, o.creep);
  avalanche(h, max_drop(o), kSweepsPerStep);
}

terrain::HeightField run(const SandOptions& o, const ProgressFn& progress, int snapshot_every,
                         const SnapshotFn& snapshot) {
  validate(o);
  terrain::HeightField h = initial_field(o);
  progress(0.0, "sand");
  for (int s = 0; s < o.steps; ++s) {
    step(h, o);
    if (snapshot_every > 0 && snapshot && (s + 1) % snapshot_every == 0) snapshot(s + 1, h);
    if ((s + 1) % 8 == 0 && !progress(static_cast<double>(s + 1) / o.steps, "")) {
      throw Cancelled();
    }
  }
  if (o.steps > 0) avalanche(h, max_drop(o), kFinalSweeps, 1e-3 * max_drop(o));
  progress(1.0, "");
  return h;
}

terrain::HeightField to_ground(const terrain::HeightField& m, const SandOptions& o) {
  const int n = m.width();
  // Downwind direction as a compass azimuth; the model's +x must point there.
  const double downwind = o.wind_from_deg + 180.0;
  // Angle (clockwise, map view) that turns the model's east (+x) to downwind.
  const double turn_deg = std::fmod(std::fmod(downwind - 90.0, 360.0) + 360.0, 360.0);
  terrain::HeightField g(n, m.height(), 0.0f, terrain::local_georeference(o.cell_m));
  const float scale = static_cast<float>(o.height_unit);
  const double quarter = turn_deg / 90.0;
  if (std::fabs(quarter - std::round(quarter)) < 1e-9) {
    // Exact quarter turns (square grids): tileable.
    const int turns = static_cast<int>(std::lround(quarter)) % 4;
    for (int row = 0; row < n; ++row) {
      for (int x = 0; x < n; ++x) {
        // Ground (x, row) <- model cell turned back by `turns` clockwise quarters.
        int mx = x, mr = row;
        for (int t = 0; t < turns; ++t) {
          const int px = mx;  // inverse of a clockwise quarter: (x, r) <- (r, n-1-x)
          mx = mr;
          mr = n - 1 - px;
        }
        g(x, row) = m(mx, mr) * scale;
      }
    }
    return g;
  }
  // Any other azimuth: sample the periodic model field along turned axes.
  const double a = turn_deg * std::numbers::pi / 180.0;
  const double c = std::cos(a), s = std::sin(a);
  const double half = 0.5 * (n - 1);
  for (int row = 0; row < n; ++row) {
    for (int x = 0; x < n; ++x) {
      // Ground offsets (east, north) from the centre, turned back by -a.
      const double e = x - half, north = half - row;
      const double me = c * e - s * north, mn = s * e + c * north;
      const double fx = me + half, fr = half - mn;
      const int x0 = static_cast<int>(std::floor(fx)), r0 = static_cast<int>(std::floor(fr));
      const float tx = static_cast<float>(fx - x0), tr = static_cast<float>(fr - r0);
      g(x, row) =
          scale * ((1 - tr) * ((1 - tx) * m.wrapped(x0, r0) + tx * m.wrapped(x0 + 1, r0)) +
                   tr * ((1 - tx) * m.wrapped(x0, r0 + 1) + tx * m.wrapped(x0 + 1, r0 + 1)));
    }
  }
  return g;
}

terrain::HeightField simulate(const SandOptions& o, const ProgressFn& progress) {
  return to_ground(run(o, progress), o);
}

}  // namespace drift::dunes
