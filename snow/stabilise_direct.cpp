#include "snow/stabilise_direct.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <queue>
#include <set>
#include <utility>
#include <vector>

#include "snow/stabilise_field.h"
#include "terrain/error.h"

namespace drift::snow {

namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

using Field = StabiliseField;

// Step 1: the drained surface (greatest fixed point of E = min(H, max(ground,
// min_n E(n) + k d))). Labels only fall, and a label set from a popped one is
// higher than it, so each is final when popped (Dijkstra).
std::vector<double> drained_surface(const Field& f) {
  std::vector<double> e(f.cells());
  for (std::size_t i = 0; i < e.size(); ++i) e[i] = f.surface(i);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (!(f.snow(i) > 0.0)) continue;
    double limit = e[i];
    f.neighbours(i, [&](std::size_t n, int k) { limit = std::min(limit, e[n] + f.drop(k)); });
    limit = std::max(limit, f.ground(i));
    if (limit < e[i]) e[i] = limit, queue.push({limit, i});
  }
  // Lowered cells are relaxed only once popped, from their final label; cells
  // never lowered were checked against their neighbours above.
  while (!queue.empty()) {
    // Named copies, not a structured binding: the lambda below captures them.
    const double v = queue.top().first;
    const std::size_t i = queue.top().second;
    queue.pop();
    if (v > e[i]) continue;
    f.neighbours(i, [&](std::size_t n, int k) {
      if (!(f.snow(n) > 0.0)) return;
      const double limit = std::max(v + f.drop(7 - k), f.ground(n));
      if (limit < e[n]) e[n] = limit, queue.push({limit, n});
    });
  }
  return e;
}

// Step 2: the next cell down, or kNone where the snow stops. From a cut cell
// it runs on over cut cells while the cut surface falls at repose or steeper
// (what lay above them is gone), and anywhere only where the surface falls
// more steeply than repose; so snow cut from a column stays on it (to be
// heaped there as a cone), and snow cut from a slope gathers at the foot of
// the cut.
std::uint32_t next_down(const Field& f, std::size_t i, const std::vector<std::uint8_t>* cut) {
  double best = -std::numeric_limits<double>::infinity();
  std::size_t next = i;
  const double hi = f.surface(i);
  f.neighbours(i, [&](std::size_t n, int k) {
    const double hn = f.surface(n), excess = hi - hn - f.drop(k);
    if (hn < hi && excess > best) best = excess, next = n;  // strictly down: no loop
  });
  if (next == i) return kNone;
  const double slack = 1e-9 * (1.0 + std::abs(hi));  // the cut's own rounding
  const bool on_cut = cut && (*cut)[i] && (*cut)[next];
  const bool moves = on_cut ? best >= -slack : best > slack;
  return moves ? static_cast<std::uint32_t>(next) : kNone;
}

// Step 3: heaps `mass` at p as the cone of slope k over the surface, over the
// connected cells around p where it stands above it. A cell c lies under the
// cone of apex T where T > t(c) = H(c) + k d(p, c), and joins p's region once T
// passes J(c), the least over paths from p of the largest t on the path. So
// the cells are flooded from p in ascending J (a priority flood, each cell
// once): with m cells joined whose t sum to S, the cone of apex T holds m T -
// S until the next joins, and the apex holding `mass` is found exactly, in one
// flood over the region (no bisection).
//
// Where a cell joins through a pass higher than itself (J(c) > t(c)), the
// volume would jump: the snow spills over the pass. The cone is then heaped
// up to the pass and the rest runs on from that cell (returned), as snow
// spills over a pass.
struct Spill {
  double mass = 0.0;
  std::size_t from = 0;
};

Spill heap_at(const Field& f, std::size_t p, double mass, std::vector<std::uint8_t>& seen,
              std::vector<std::size_t>& region, std::uint8_t* marks) {
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> flood;
  std::vector<std::size_t> touched;
  auto t_of = [&](std::size_t c) { return f.surface(c) + f.cone_drop(p, c); };
  region.clear();
  flood.push({f.surface(p), p}), seen[p] = 1, touched.push_back(p);
  double sum_t = 0.0, apex = 0.0;
  Spill spill;
  for (;;) {
    if (flood.empty()) {  // the whole grid joined
      apex = (mass + sum_t) / static_cast<double>(region.size());
      break;
    }
    const double j = flood.top().first;  // captured below: no structured binding
    const std::size_t c = flood.top().second;
    const double m = static_cast<double>(region.size());
    if (!region.empty() && m * j - sum_t >= mass) {  // the apex lies before c joins
      apex = (mass + sum_t) / m;
      break;
    }
    const double t = t_of(c);
    if (!region.empty() && j - t > 1e-7 * (1.0 + std::abs(j))) {  // c joins over a pass: spill
      apex = j;
      spill.mass = mass - (m * j - sum_t);
      spill.from = c;
      mass -= spill.mass;
      break;
    }
    flood.pop();
    region.push_back(c), sum_t += t;
    f.neighbours(c, [&](std::size_t n, int) {
      if (!seen[n]) seen[n] = 1, touched.push_back(n), flood.push({std::max(j, t_of(n)), n});
    });
  }
  for (std::size_t c : touched) seen[c] = 0;
  // Layers under 1 nm (rounding at the region's rim) are left to the apex
  // cell, so that no film is left on a face steeper than repose. When the
  // heap spills, the cells at the pass's level (within the pass tolerance
  // above, their layer thinner than it) are the pass itself, whose ground
  // may fall to the spill cell more steeply than repose: their layer spills
  // on with the rest instead of lying there as a film.
  const double film = spill.mass > 0.0 ? std::max(1e-9, 1e-7 * (1.0 + std::abs(apex))) : 1e-9;
  double total = 0.0, withheld = 0.0;
  for (std::size_t c : region) {
    if (marks) marks[c] = 1;
    double add = apex - t_of(c);
    if (!(add > film)) {
      if (spill.mass > 0.0 && add > 0.0) withheld += add;
      add = 0.0;
    }
    f.snow(c) += add, total += add;
  }
  f.snow(p) += (mass - withheld) - total;  // the rounding, to the apex cell
  spill.mass += withheld;
  return spill;
}

// Where snow set down at i on the surface as it is now comes to rest (the
// cells below have been heaped since the cut, so no memo).
std::size_t runs_to(const Field& f, std::size_t i) {
  for (;;) {
    const std::uint32_t next = next_down(f, i, nullptr);
    if (next == kNone) return i;
    i = next;
  }
}

// Step 2, as the passes share it: the loose snow runs down to every
// neighbour the surface falls to more steeply than repose, in proportion to
// the excess (paper 003 2.1(3), the passes' rule; over cut cells also where
// the cut surface falls at repose), and rests where nothing is steeper.
// Cells are taken from the highest down, so each has all its inflow when it
// is taken (every flow goes strictly down); the last receiver gets the
// remainder, so mass moves as the same doubles.
void route_shared(const Field& f, const std::vector<std::uint32_t>& cut_cells,
                  const std::vector<double>& loose, const std::vector<std::uint8_t>& cut,
                  std::vector<double>& load, std::vector<std::uint32_t>& heaps,
                  DirectReport& report, std::uint8_t* touched) {
  using Item = std::pair<double, std::uint32_t>;
  std::priority_queue<Item> queue;                // highest surface first; ties by index
  std::vector<double>& flow = load;               // pending inflow; becomes the load where it rests
  std::vector<std::uint8_t> state(f.cells(), 0);  // 1 queued, 2 resting
  for (std::size_t c = 0; c < cut_cells.size(); ++c) {
    flow[cut_cells[c]] += loose[c], report.loose += loose[c];
    if (!state[cut_cells[c]])
      state[cut_cells[c]] = 1, queue.push({f.surface(cut_cells[c]), cut_cells[c]});
  }
  std::array<std::size_t, 8> to{};
  std::array<double, 8> share{};
  while (!queue.empty()) {
    const std::uint32_t i = queue.top().second;
    queue.pop();
    if (touched) touched[i] = 1;  // snow passed or rests here
    const double hi = f.surface(i), slack = 1e-9 * (1.0 + std::abs(hi));
    int m = 0;
    double sum = 0.0, best = -std::numeric_limits<double>::infinity();
    std::size_t steepest = i;
    f.neighbours(i, [&](std::size_t n, int k) {
      const double hn = f.surface(n), excess = hi - hn - f.drop(k);
      if (!(hn < hi)) return;
      if (excess > best) best = excess, steepest = n;
      if (excess > slack) to[m] = n, share[m] = excess, sum += excess, ++m;
    });
    if (m == 0 && steepest != i && cut[i] && cut[steepest] && best >= -slack)
      to[0] = steepest, share[0] = 1.0, sum = 1.0, m = 1;  // down the cut at repose
    if (m == 0) {
      state[i] = 2, heaps.push_back(i);
      continue;
    }
    const double amount = flow[i];
    flow[i] = 0.0;
    double given = 0.0;
    for (int j = 0; j < m; ++j) {
      const double part = j + 1 == m ? amount - given : amount * (share[j] / sum);
      given += part;
      flow[to[j]] += part;
      if (!state[to[j]])
        state[to[j]] = 1, queue.push({f.surface(to[j]), static_cast<std::uint32_t>(to[j])});
    }
  }
}

}  // namespace

DirectReport settle_at_rest(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                            double dx, double dy, double tan_repose, int layers,
                            std::vector<std::uint8_t>* touched) {
  if (touched && touched->size() != snow.size()) touched->assign(snow.size(), 0);
  if (layers < 1) throw Error("settle_at_rest: the number of layers must be at least 1");
  if (layers > 1) {
    // Each layer is all / layers, the last what the others left (summed the
    // same way per cell), so the layers add up to the snow given.
    const terrain::Grid<double> all = snow;
    std::fill(snow.values().begin(), snow.values().end(), 0.0);
    DirectReport report;
    for (int j = 1; j <= layers; ++j) {
      for (std::size_t i = 0; i < snow.size(); ++i) {
        const double piece = all.values()[i] / layers;
        double layer = piece;
        if (j == layers) {
          double before = 0.0;
          for (int l = 1; l < layers; ++l) before += piece;
          layer = all.values()[i] - before;
        }
        snow.values()[i] += layer;
      }
      const DirectReport r = settle_at_rest(ground, snow, dx, dy, tan_repose, 1, touched);
      report.cut_cells += r.cut_cells, report.heaps += r.heaps, report.spills += r.spills;
      report.loose += r.loose;
    }
    return report;
  }
  if (ground.width() != snow.width() || ground.height() != snow.height())
    throw Error("settle_at_rest: ground and snow grids differ in size");
  if (snow.size() >= kNone)
    throw Error("settle_at_rest: more than 2^32 - 1 cells; settle the raster in parts");
  const Field f(ground, snow, dx, dy, tan_repose);
  DirectReport report;
  // The drained surface's array holds each resting cell's load once the cut is made.
  std::vector<double> drained_then_load = drained_surface(f);
  std::vector<std::uint8_t> cut(f.cells(), 0);
  std::vector<std::uint32_t> cut_cells;
  std::vector<double> loose;
  for (std::size_t i = 0; i < f.cells(); ++i) {
    if (!(drained_then_load[i] < f.surface(i))) continue;
    const double before = f.snow(i);
    f.snow(i) = std::max(drained_then_load[i] - f.ground(i), 0.0);
    loose.push_back(before - f.snow(i));
    cut[i] = 1;
    if (touched) (*touched)[i] = 1;
    cut_cells.push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<double>& load = drained_then_load;
  std::fill(load.begin(), load.end(), 0.0);
  std::vector<std::uint32_t> heaps;
  std::uint8_t* const marks = touched ? touched->data() : nullptr;
  route_shared(f, cut_cells, loose, cut, load, heaps, report, marks);
  // Heaps in ascending cell order; spilled snow queued at its new resting
  // cell (a fixed order, so the same bits on any machine).
  std::set<std::size_t> queue(heaps.begin(), heaps.end());
  std::vector<std::uint8_t>& seen = cut;  // from here heap_at's marks, all clear
  std::fill(seen.begin(), seen.end(), std::uint8_t{0});
  std::vector<std::size_t> region;
  while (!queue.empty()) {
    const std::size_t p = *queue.begin();
    queue.erase(queue.begin());
    const double mass = load[p];
    load[p] = 0.0;
    if (!(mass > 0.0)) continue;
    const Spill spill = heap_at(f, p, mass, seen, region, marks);
    if (spill.mass > 0.0) {
      ++report.spills;
      std::size_t r = runs_to(f, spill.from);
      if (r == p) r = spill.from;  // back into its own heap: rest where it spilled
      load[r] += spill.mass;
      queue.insert(r);
    }
  }
  report.cut_cells = cut_cells.size();
  report.heaps = heaps.size();
  return report;
}

}  // namespace drift::snow
