#include "terrain/slope_relax.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace drift::terrain {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Neighbour {
  int dx, dy;
};
constexpr std::array<Neighbour, 8> kNeighbours{
    {{-1, -1}, {0, -1}, {1, -1}, {-1, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}}};

struct Flow {
  int from, to;
  double amount;  // m of height
};

const SlopeRule& rule_at(const SlopeCells& cells, int index) {
  if (!cells.rule_of_cell) return cells.rules[0];
  return cells.rules[cells.rule_of_cell->values()[static_cast<std::size_t>(index)]];
}

double bound(const Grid<double>* grid, int index, double none) {
  return grid ? grid->values()[static_cast<std::size_t>(index)] : none;
}

}  // namespace

void SlopeRelaxWorkspace::fit(std::size_t cells) {
  if (seen_.size() == cells) return;
  seen_.assign(cells, 0);
  in_.assign(cells, 0.0);
  in_excess_.assign(cells, 0.0);
  epoch_ = 0;
}

// One relaxation call's passes over its workspace.
struct SlopeRelaxPass {
  Grid<double>& h;
  const SlopeCells& cells;
  const SlopeRelaxOptions& o;
  SlopeRelaxWorkspace& ws;
  std::array<double, 8> distance{};
  std::vector<Flow> flows;
  std::vector<int> receivers;

  SlopeRelaxPass(Grid<double>& heights, const SlopeCells& c, const SlopeRelaxOptions& options,
                 SlopeRelaxWorkspace& w)
      : h(heights), cells(c), o(options), ws(w) {
    for (int k = 0; k < 8; ++k)
      distance[k] = std::hypot(kNeighbours[k].dx * o.dx, kNeighbours[k].dy * o.dy);
  }

  std::uint32_t next_epoch() {
    if (++ws.epoch_ == 0) std::fill(ws.seen_.begin(), ws.seen_.end(), 0), ws.epoch_ = 1;
    return ws.epoch_;
  }
  // Appends `index` to `list` unless it is already there this epoch.
  void list_once(int index, std::vector<int>& list) {
    std::uint32_t& s = ws.seen_[static_cast<std::size_t>(index)];
    if (s != ws.epoch_) s = ws.epoch_, list.push_back(index);
  }

  void clear_offers() {
    for (int n : receivers) {
      ws.in_[static_cast<std::size_t>(n)] = 0.0;
      ws.in_excess_[static_cast<std::size_t>(n)] = 0.0;
    }
  }

  // The flows out of one cell, scaled so that it gives at most half its largest
  // excess and never sinks below its floor; a cell at its ceiling is held.
  void donor_flows(int index) {
    const SlopeRule& rule = rule_at(cells, index);
    if (!std::isfinite(rule.tan_repose)) return;
    const int w = h.width(), x = index % w, y = index / w;
    const double hc = h.values()[static_cast<std::size_t>(index)];
    if (hc >= bound(cells.ceiling, index, kInf)) return;
    const std::size_t first = flows.size();
    double out = 0.0, largest = 0.0;
    for (int k = 0; k < 8; ++k) {
      const int nx = x + kNeighbours[k].dx, ny = y + kNeighbours[k].dy;
      if (nx < 0 || ny < 0 || nx >= w || ny >= h.height()) continue;
      const int n = ny * w + nx;
      const double e = hc - h.values()[static_cast<std::size_t>(n)] - rule.tan_repose * distance[k];
      if (e <= o.tolerance) continue;
      flows.push_back({index, n, rule.fraction * e});
      out += rule.fraction * e;
      largest = std::max(largest, e);
      if (ws.in_[static_cast<std::size_t>(n)] == 0.0) receivers.push_back(n);
      ws.in_[static_cast<std::size_t>(n)] += rule.fraction * e;  // before the donor's scale
      double& ex = ws.in_excess_[static_cast<std::size_t>(n)];
      ex = std::max(ex, e);
    }
    if (out <= 0.0) return;
    const double room = hc - bound(cells.floor, index, -kInf);
    const double scale = std::min({1.0, 0.5 * largest / out, std::max(room, 0.0) / out});
    if (scale < 1.0)
      for (std::size_t i = first; i < flows.size(); ++i) flows[i].amount *= scale;
  }

  // A receiver takes at most half the largest excess it is offered from and
  // never rises above its ceiling (offers counted before donors' scaling, so
  // the cap is conservative).
  double receiver_scale(int n) const {
    const std::size_t i = static_cast<std::size_t>(n);
    const double in = ws.in_[i];
    if (!(in > 0.0)) return 0.0;
    const double room = bound(cells.ceiling, n, kInf) - h.values()[i];
    return std::min({1.0, 0.5 * ws.in_excess_[i] / in, std::max(room, 0.0) / in});
  }
};

SlopeRelaxReport relax_slopes(Grid<double>& heights, std::vector<int> active,
                              const SlopeCells& cells, const SlopeRelaxOptions& options,
                              std::vector<int>& moved_cells, Grid<float>* disturbed,
                              SlopeRelaxWorkspace* workspace) {
  SlopeRelaxWorkspace local;
  SlopeRelaxWorkspace& ws = workspace ? *workspace : local;
  ws.fit(heights.size());
  SlopeRelaxPass pass(heights, cells, options, ws);
  SlopeRelaxReport report;
  moved_cells.clear();
  std::vector<int> next, listed;
  std::vector<double>& h = heights.values();
  const int w = heights.width(), hgt = heights.height();
  pass.next_epoch();
  for (int c : active) pass.list_once(c, next);
  active.swap(next);
  while (!active.empty() && report.passes < options.max_passes) {
    ++report.passes;
    pass.flows.clear();
    pass.receivers.clear();
    for (int index : active) pass.donor_flows(index);
    for (Flow& f : pass.flows) {
      const double s = pass.receiver_scale(f.to);
      f.amount *= s;
    }
    pass.clear_offers();
    next.clear();
    pass.next_epoch();
    for (const Flow& f : pass.flows) {
      if (!(f.amount > 0.0)) continue;
      h[static_cast<std::size_t>(f.from)] -= f.amount;
      h[static_cast<std::size_t>(f.to)] += f.amount;
      report.moved += f.amount;
      if (disturbed) {
        disturbed->values()[static_cast<std::size_t>(f.from)] += static_cast<float>(f.amount);
        disturbed->values()[static_cast<std::size_t>(f.to)] += static_cast<float>(f.amount);
      }
      listed.push_back(f.from), listed.push_back(f.to);
      for (int end : {f.from, f.to}) {
        const int x = end % w, y = end / w;
        pass.list_once(end, next);
        for (const Neighbour& nb : kNeighbours) {
          const int nx = x + nb.dx, ny = y + nb.dy;
          if (nx >= 0 && ny >= 0 && nx < w && ny < hgt) pass.list_once(ny * w + nx, next);
        }
      }
    }
    active.swap(next);
  }
  report.converged = active.empty();
  pass.next_epoch();
  for (int c : listed) pass.list_once(c, moved_cells);
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
      if (std::isfinite(bound(cells.ceiling, n, kInf))) continue;
      const double d = std::hypot(nb.dx * options.dx, nb.dy * options.dy);
      worst =
          std::max(worst, heights.values()[static_cast<std::size_t>(index)] -
                              heights.values()[static_cast<std::size_t>(n)] - rule.tan_repose * d);
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
