#include "snow/stabilise_direct.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <queue>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "snow/stabilise_field.h"
#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::snow {

namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

using Field = StabiliseField;

// The cells whose snow can move at all: a cell's drained surface E is at
// least min_n (ground(n) + k d) (E(n) >= ground(n)), so where the snow's
// surface stands no higher than that over every neighbour nothing is cut (and
// nothing runs onto a cell unless something is cut). A bound on the cut, known
// before anything is allocated: 0 on ground where nothing slides.
std::size_t cells_that_can_move(const Field& f) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < f.cells(); ++i) {
    if (!(f.snow(i) > 0.0)) continue;
    const double hi = f.surface(i);
    bool moves = false;
    f.neighbours(i, [&](std::size_t n, int k) { moves = moves || hi > f.ground(n) + f.drop(k); });
    count += moves;
  }
  return count;
}

// A binary min-heap of cells ordered by (label, index), at most one entry a
// cell (its label lowered in place): the heap holds at most the cells that
// can move, where a queue of (label, cell) pairs holds one entry a lowering.
// The label is kept in the entry, so that comparing two reads no scattered
// memory; 4 bytes a cell for the positions. Pops in the same order as such a
// queue would (a strict order), so the same bits.
struct Labelled {
  double label;
  std::uint32_t cell;
};
class CellHeap {
 public:
  CellHeap(std::size_t cells, std::vector<Labelled>& heap) : heap_(heap), pos_(cells, kNone) {
    heap_.clear();
  }
  bool empty() const { return heap_.empty(); }
  // Adds cell i with `label`, or moves it up after its label fell to `label`.
  void lowered(std::uint32_t i, double label) {
    if (pos_[i] == kNone) {
      heap_.push_back({label, i});
      up(heap_.size() - 1);
    } else {
      heap_[pos_[i]].label = label;
      up(pos_[i]);
    }
  }
  Labelled pop() {
    const Labelled top = heap_.front();
    pos_[top.cell] = kNone;
    const Labelled last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) heap_.front() = last, pos_[last.cell] = 0, down(0);
    return top;
  }

 private:
  static bool before(const Labelled& a, const Labelled& b) {
    return a.label < b.label || (a.label == b.label && a.cell < b.cell);
  }
  void place(std::size_t at, const Labelled& entry) {
    heap_[at] = entry, pos_[entry.cell] = static_cast<std::uint32_t>(at);
  }
  void up(std::size_t at) {
    const Labelled entry = heap_[at];
    while (at > 0) {
      const std::size_t parent = (at - 1) / 2;
      if (!before(entry, heap_[parent])) break;
      place(at, heap_[parent]), at = parent;
    }
    place(at, entry);
  }
  void down(std::size_t at) {
    const Labelled entry = heap_[at];
    const std::size_t n = heap_.size();
    for (;;) {
      std::size_t child = 2 * at + 1;
      if (child >= n) break;
      if (child + 1 < n && before(heap_[child + 1], heap_[child])) ++child;
      if (!before(heap_[child], entry)) break;
      place(at, heap_[child]), at = child;
    }
    place(at, entry);
  }
  std::vector<Labelled>& heap_;
  std::vector<std::uint32_t> pos_;
};

// Step 1: the drained surface (greatest fixed point of E = min(H, max(ground,
// min_n E(n) + k d))) into e. Labels only fall, and a label set from a popped
// one is higher than it, so each is final when popped (Dijkstra). `heap`:
// room for the lowered cells (at most those cells_that_can_move counts).
void drained_surface(const Field& f, std::vector<double>& e, std::vector<Labelled>& heap) {
  for (std::size_t i = 0; i < e.size(); ++i) e[i] = f.surface(i);
  CellHeap queue(e.size(), heap);
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (!(f.snow(i) > 0.0)) continue;
    double limit = e[i];
    f.neighbours(i, [&](std::size_t n, int k) { limit = std::min(limit, e[n] + f.drop(k)); });
    limit = std::max(limit, f.ground(i));
    if (limit < e[i]) e[i] = limit, queue.lowered(static_cast<std::uint32_t>(i), limit);
  }
  // Lowered cells are relaxed only once popped, from their final label; cells
  // never lowered were checked against their neighbours above.
  while (!queue.empty()) {
    const Labelled top = queue.pop();
    const std::uint32_t i = top.cell;
    const double v = top.label;
    f.neighbours(i, [&](std::size_t n, int k) {
      if (!(f.snow(n) > 0.0)) return;
      const double limit = std::max(v + f.drop(7 - k), f.ground(n));
      if (limit < e[n]) e[n] = limit, queue.lowered(static_cast<std::uint32_t>(n), limit);
    });
  }
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
                  std::vector<double>& load, std::vector<std::pair<double, std::uint32_t>>& room,
                  std::vector<std::uint32_t>& heaps, DirectReport& report,
                  std::uint8_t* touched) {
  // Highest surface first, ties by index; each cell queued once, in `room`
  // (one entry a cell at most, reserved by the caller).
  using Item = std::pair<double, std::uint32_t>;
  room.clear();
  std::priority_queue<Item> queue(std::less<Item>(), std::move(room));
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
  // Counted before each allocation, from what this layer will hold (the
  // caller's grids are held by stabilise_grid's HeldMemory): nothing where no
  // snow can move (the state is at rest as it is); else, while the drained
  // surface is found, its array (then the loads) 8 bytes a cell, the heap's
  // positions 4 and an entry of 16 for each cell that can move; then, once it
  // says how many cells are cut, the loads, the cut marks and the routing
  // state (1 each), the routing queue's room (16: one entry a cell at most,
  // reserved; its pages are touched only as far as it fills) and 12 a cut
  // cell, its index and loose snow (MemoryEstimate.
  // SnowFallDirectOnFlatAndSteepGround: the worst case, a queue entry and a
  // cut cell for every cell, counted up front, was 1.5-1.85 times the peak
  // where nothing slides).
  const std::uint64_t cells = f.cells();
  const std::size_t can_move = cells_that_can_move(f);
  if (can_move == 0) return report;
  const std::string what = "snow stabilisation's workspace (direct)";
  const std::string fix = "use a smaller or coarser ground raster";
  require_memory(cells * 12 + can_move * sizeof(Labelled), what, fix);
  // The drained surface's array holds each resting cell's load once the cut is made.
  std::vector<double> drained_then_load(cells);
  {
    std::vector<Labelled> heap;
    heap.reserve(can_move);
    drained_surface(f, drained_then_load, heap);
  }
  std::size_t cut_count = 0;
  for (std::size_t i = 0; i < f.cells(); ++i) cut_count += drained_then_load[i] < f.surface(i);
  require_memory(cells * (8 + 1 + 1 + 16) + cut_count * 12, what, fix);
  std::vector<std::pair<double, std::uint32_t>> room;
  room.reserve(cells);
  std::vector<std::uint8_t> cut(f.cells(), 0);
  std::vector<std::uint32_t> cut_cells;
  std::vector<double> loose;
  cut_cells.reserve(cut_count), loose.reserve(cut_count);
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
  route_shared(f, cut_cells, loose, cut, load, room, heaps, report, marks);
  // The heaps' list and their queue's nodes (about 48 bytes each), beside the
  // loads and marks (the routing's state and room are freed).
  require_memory(cells * 9 + cut_count * 12 + heaps.size() * (4 + 48), what, fix);
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
