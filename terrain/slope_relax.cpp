#include "terrain/slope_relax.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace drift::terrain {

namespace {

struct Neighbour {
  int dx, dy;
};
constexpr std::array<Neighbour, 8> kNeighbours{
    {{-1, -1}, {0, -1}, {1, -1}, {-1, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}}};

struct Flow {
  int from, to;
  double amount;  // m of height
  double excess;  // the pair's excess over repose before the pass
};

const SlopeRule& rule_at(const SlopeCells& cells, int index) {
  if (!cells.rule_of_cell) return cells.rules[0];
  return cells.rules[cells.rule_of_cell->values()[static_cast<std::size_t>(index)]];
}

double bound(const Grid<double>* grid, int index, double none) {
  return grid ? static_cast<double>(grid->values()[static_cast<std::size_t>(index)]) : none;
}

// The flows out of one cell, scaled so that it gives at most half its largest
// excess and never sinks below its floor.
void donor_flows(const Grid<double>& h, const SlopeCells& cells, const SlopeRelaxOptions& o,
                 int index, std::vector<Flow>& flows) {
  const SlopeRule& rule = rule_at(cells, index);
  if (!std::isfinite(rule.tan_repose)) return;
  const int w = h.width(), x = index % w, y = index / w;
  const double hc = h.values()[static_cast<std::size_t>(index)];
  // A cell pressed against its ceiling (an object standing on it) is held there.
  if (hc >= bound(cells.ceiling, index, std::numeric_limits<double>::infinity())) return;
  const std::size_t first = flows.size();
  double out = 0.0, largest = 0.0;
  for (const Neighbour& nb : kNeighbours) {
    const int nx = x + nb.dx, ny = y + nb.dy;
    if (nx < 0 || ny < 0 || nx >= w || ny >= h.height()) continue;
    const double d = std::hypot(nb.dx * o.dx, nb.dy * o.dy);
    const int n = ny * w + nx;
    const double e = hc - h.values()[static_cast<std::size_t>(n)] - rule.tan_repose * d;
    if (e <= o.tolerance) continue;
    flows.push_back({index, n, rule.fraction * e, e});
    out += rule.fraction * e;
    largest = std::max(largest, e);
  }
  if (out <= 0.0) return;
  const double room = hc - bound(cells.floor, index, -std::numeric_limits<double>::infinity());
  const double scale = std::min({1.0, 0.5 * largest / out, std::max(room, 0.0) / out});
  if (scale < 1.0)
    for (std::size_t i = first; i < flows.size(); ++i) flows[i].amount *= scale;
}

// Scales the flows into each receiver so that it takes at most half the largest
// excess it receives from and never rises above its ceiling. Sorts by receiver.
void cap_receivers(const Grid<double>& h, const SlopeCells& cells, std::vector<Flow>& flows) {
  std::stable_sort(flows.begin(), flows.end(),
                   [](const Flow& a, const Flow& b) { return a.to < b.to; });
  for (std::size_t i = 0; i < flows.size();) {
    std::size_t j = i;
    double in = 0.0, largest = 0.0;
    for (; j < flows.size() && flows[j].to == flows[i].to; ++j) {
      in += flows[j].amount;
      largest = std::max(largest, flows[j].excess);
    }
    const int n = flows[i].to;
    const double hn = h.values()[static_cast<std::size_t>(n)];
    const double room = bound(cells.ceiling, n, std::numeric_limits<double>::infinity()) - hn;
    const double scale = in > 0.0 ? std::min({1.0, 0.5 * largest / in, std::max(room, 0.0) / in})
                                  : 0.0;
    if (scale < 1.0)
      for (std::size_t k = i; k < j; ++k) flows[k].amount *= scale;
    i = j;
  }
}

void activate_around(int index, int w, int h, std::vector<int>& next) {
  const int x = index % w, y = index / w;
  next.push_back(index);
  for (const Neighbour& nb : kNeighbours) {
    const int nx = x + nb.dx, ny = y + nb.dy;
    if (nx >= 0 && ny >= 0 && nx < w && ny < h) next.push_back(ny * w + nx);
  }
}

void sort_unique(std::vector<int>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

}  // namespace

SlopeRelaxReport relax_slopes(Grid<double>& heights, std::vector<int> active,
                              const SlopeCells& cells, const SlopeRelaxOptions& options,
                              std::vector<int>& moved_cells, Grid<float>* disturbed) {
  SlopeRelaxReport report;
  moved_cells.clear();
  std::vector<Flow> flows;
  std::vector<int> next;
  const int w = heights.width(), hgt = heights.height();
  std::vector<double>& h = heights.values();
  sort_unique(active);
  while (!active.empty() && report.passes < options.max_passes) {
    ++report.passes;
    flows.clear();
    for (int index : active) donor_flows(heights, cells, options, index, flows);
    cap_receivers(heights, cells, flows);
    next.clear();
    for (const Flow& f : flows) {
      if (!(f.amount > 0.0)) continue;
      h[static_cast<std::size_t>(f.from)] -= f.amount;
      h[static_cast<std::size_t>(f.to)] += f.amount;
      report.moved += f.amount;
      if (disturbed) {
        disturbed->values()[static_cast<std::size_t>(f.from)] += static_cast<float>(f.amount);
        disturbed->values()[static_cast<std::size_t>(f.to)] += static_cast<float>(f.amount);
      }
      moved_cells.push_back(f.from);
      moved_cells.push_back(f.to);
      activate_around(f.from, w, hgt, next);
      activate_around(f.to, w, hgt, next);
    }
    sort_unique(next);
    active.swap(next);
  }
  report.converged = active.empty();
  sort_unique(moved_cells);
  return report;
}

double max_slope_excess(const Grid<double>& heights, const SlopeCells& cells,
                        const SlopeRelaxOptions& options, std::span<const int> only) {
  const int w = heights.width(), hgt = heights.height();
  double worst = 0.0;
  auto visit = [&](int index) {
    const SlopeRule& rule = rule_at(cells, index);
    if (!std::isfinite(rule.tan_repose)) return;
    const int x = index % w, y = index / w;
    for (const Neighbour& nb : kNeighbours) {
      const int nx = x + nb.dx, ny = y + nb.dy;
      if (nx < 0 || ny < 0 || nx >= w || ny >= hgt) continue;
      const int n = ny * w + nx;
      if (std::isfinite(bound(cells.ceiling, n, std::numeric_limits<double>::infinity())))
        continue;
      const double d = std::hypot(nb.dx * options.dx, nb.dy * options.dy);
      worst = std::max(worst, heights.values()[static_cast<std::size_t>(index)] -
                                  heights.values()[static_cast<std::size_t>(n)] -
                                  rule.tan_repose * d);
    }
  };
  if (only.empty()) {
    for (int i = 0; i < w * hgt; ++i) visit(i);
  } else {
    for (int i : only) visit(i);
  }
  return worst;
}

}  // namespace drift::terrain
