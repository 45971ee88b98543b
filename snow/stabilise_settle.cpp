#include "snow/stabilise_settle.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <queue>
#include <utility>

#include "snow/stabilise_field.h"

namespace drift::snow {

namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

// The grid's snow (stabilise_field.h) with the settling's tolerances.
class SnowSurface : public StabiliseField {
 public:
  SnowSurface(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
              const SettleGeometry& geo)
      : StabiliseField(ground, snow, geo.dx, geo.dy, geo.tan_repose), geo_(geo) {}
  double tolerance() const { return geo_.tolerance; }
  // Excess below which snow running off the cut comes to rest: 10 x tol (1 cm
  // at the default), so that a heap still settling counts as a resting place.
  double rest_tolerance() const { return 10.0 * geo_.tolerance; }
  // Snow deeper than this (100 x tol, 10 cm at the default) is a deposit:
  // snow running onto it stops there, at its upper edge, as the passes would
  // stop it, instead of running on down its flank.
  double deposit_depth() const { return 100.0 * geo_.tolerance; }

 private:
  SettleGeometry geo_;
};

// Step 1: the repose envelope (largest fixed point of E = max(ground, min(H,
// min_n E(n) + k d + tol)) on cells holding more than tol), by Dijkstra from the
// cells that break it: labels only fall and each is final when popped.
std::vector<double> repose_envelope(const SnowSurface& s) {
  const double tol = s.tolerance();
  std::vector<double> e(s.cells());
  for (std::size_t i = 0; i < e.size(); ++i) e[i] = s.surface(i);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  auto lower = [&](std::size_t i, double limit) {
    limit = std::max(limit, s.ground(i));
    if (limit < e[i]) e[i] = limit, queue.push({limit, i});
  };
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (!(s.snow(i) > tol)) continue;
    for (int k = 0; k < 8; ++k)
      if (s.inside(i, k) && !(s.snow(s.neighbour(i, k)) > tol))  // anchored on bare cells
        lower(i, e[s.neighbour(i, k)] + s.drop(k) + tol);
  }
  while (!queue.empty()) {
    const auto [v, i] = queue.top();
    queue.pop();
    if (v > e[i]) continue;  // lowered again since it was queued
    for (int k = 0; k < 8; ++k) {
      if (!s.inside(i, k)) continue;
      const std::size_t n = s.neighbour(i, k);
      if (s.snow(n) > tol) lower(n, v + s.drop(7 - k) + tol);
    }
  }
  return e;
}

// Step 2: the next cell down the steepest excess, or kNone where the snow comes
// to rest. Cut snow runs down the cut surface while it is at repose or steeper
// (excess >= -tol: what lay above it is gone); once off it, it moves as the
// passes move snow, only where the excess is above tol.
std::size_t next_down(const SnowSurface& s, std::size_t i, bool cut) {
  double best = -std::numeric_limits<double>::infinity();
  std::size_t next = kNone;
  const double hi = s.surface(i);
  for (int k = 0; k < 8; ++k) {
    if (!s.inside(i, k)) continue;
    const std::size_t n = s.neighbour(i, k);
    const double excess = hi - s.surface(n) - s.drop(k);
    if (excess > best && hi > s.surface(n)) best = excess, next = n;  // strictly down: no loop
  }
  const bool moves =
      cut ? best >= -s.tolerance() : best > s.rest_tolerance() && s.snow(i) <= s.deposit_depth();
  return moves ? next : kNone;
}

// The cell where snow set loose at i comes to rest, memoised along the path;
// `cut` marks the cells the envelope cut (snow runs on down a cut surface).
std::size_t resting_cell(const SnowSurface& s, std::size_t i, const std::vector<std::uint8_t>& cut,
                         std::vector<std::size_t>& rest, std::vector<std::size_t>& path) {
  path.clear();
  std::size_t c = i;
  while (rest[c] == kNone) {
    path.push_back(c);
    const std::size_t next = next_down(s, c, cut[c] != 0);
    if (next == kNone) {
      rest[c] = c;
      break;
    }
    c = next;
  }
  for (std::size_t p : path) rest[p] = rest[c];
  return rest[c];
}

// Step 3: the snow a cone of apex height `apex` at p holds over the surface,
// over the cells connected to p where it stands above the surface and its layer
// does not thicken away from p by more than tol a step (a cone reaching out
// over a cliff would hold snow the cliff cannot: that snow is the passes' to
// move). The cells are listed in `region`, p first.
double cone_volume(const SnowSurface& s, std::size_t p, double apex,
                   std::vector<std::size_t>& region, std::vector<std::uint8_t>& seen) {
  region.clear();
  if (!(apex > s.surface(p))) return 0.0;
  region.push_back(p), seen[p] = 1;
  double volume = 0.0;
  for (std::size_t r = 0; r < region.size(); ++r) {
    const std::size_t c = region[r];
    const double layer = apex - s.cone_drop(p, c) - s.surface(c);
    volume += layer;
    for (int k = 0; k < 8; ++k) {
      if (!s.inside(c, k)) continue;
      const std::size_t n = s.neighbour(c, k);
      const double next = apex - s.cone_drop(p, n) - s.surface(n);
      if (!seen[n] && next > 0.0 && next <= layer + s.rest_tolerance())
        seen[n] = 1, region.push_back(n);
    }
  }
  for (std::size_t c : region) seen[c] = 0;
  return volume;
}

// Heaps `mass` (m of snow x cells) at p as the cone of slope k over the surface;
// appends the cells it raised to `changed`.
void heap_at(const SnowSurface& s, std::size_t p, double mass, std::vector<std::uint8_t>& seen,
             std::vector<std::size_t>& changed) {
  std::vector<std::size_t> region;
  double lo = s.surface(p), hi = lo + mass;  // the cone at hi holds at least `mass`
  for (int it = 0; it < 200 && hi - lo > 1e-9 * (1.0 + std::abs(hi)); ++it) {
    const double mid = 0.5 * (lo + hi);
    (cone_volume(s, p, mid, region, seen) < mass ? lo : hi) = mid;
  }
  cone_volume(s, p, hi, region, seen);
  std::vector<double> add(region.size());
  double total = 0.0;
  for (std::size_t r = 0; r < region.size(); ++r)
    add[r] = hi - s.cone_drop(p, region[r]) - s.surface(region[r]), total += add[r];
  // The region grows in steps as the apex rises, so the cone may hold a little
  // more than `mass`: scale the layer down, then hand the rounding to p.
  if (total > mass)
    for (double& a : add) a *= mass / total;
  total = 0.0;
  for (double a : add) total += a;
  add[0] += mass - total;
  for (std::size_t r = 0; r < region.size(); ++r) s.snow(region[r]) += add[r];
  changed.insert(changed.end(), region.begin(), region.end());
}

}  // namespace

std::vector<std::size_t> settle_unsupported(const terrain::Grid<float>& ground,
                                            terrain::Grid<double>& snow,
                                            const SettleGeometry& geometry) {
  const SnowSurface s(ground, snow, geometry);
  // The envelope's array holds each resting cell's load once the cut is made
  // (a grid of doubles fewer: 128 MiB at 4096^2); the loose snow is kept for
  // the cut cells only, and a byte a cell says which they are.
  std::vector<double> envelope_then_load = repose_envelope(s);
  std::vector<std::size_t> changed;
  std::vector<double> loose;
  std::vector<std::uint8_t> cut(s.cells(), 0);
  for (std::size_t i = 0; i < s.cells(); ++i) {
    if (!(envelope_then_load[i] < s.surface(i))) continue;
    const double before = s.snow(i);
    s.snow(i) = std::max(envelope_then_load[i] - s.ground(i), 0.0);
    loose.push_back(before - s.snow(i));
    cut[i] = loose.back() > 0.0;
    changed.push_back(i);
  }
  std::vector<double>& load = envelope_then_load;
  std::fill(load.begin(), load.end(), 0.0);
  std::vector<std::size_t> rest(s.cells(), kNone), path, heaps;
  for (std::size_t k = 0; k < changed.size(); ++k) {
    const std::size_t r = resting_cell(s, changed[k], cut, rest, path);
    heaps.push_back(r);
    load[r] += loose[k];
  }
  std::sort(heaps.begin(), heaps.end());
  heaps.erase(std::unique(heaps.begin(), heaps.end()), heaps.end());
  std::vector<std::uint8_t>& seen = cut;  // from here: heap_at's marks, all clear
  std::fill(seen.begin(), seen.end(), std::uint8_t{0});
  for (std::size_t p : heaps) heap_at(s, p, load[p], seen, changed);
  std::sort(changed.begin(), changed.end());
  changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
  return changed;
}

}  // namespace drift::snow
