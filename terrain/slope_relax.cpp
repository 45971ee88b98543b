#include "terrain/slope_relax.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <utility>

#include "terrain/hash.h"
#include "terrain/neighbours.h"
#include "terrain/parallel.h"

namespace drift::terrain {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kTile = 16;
// Tiles in a phase below which it runs on the calling thread (marks' small
// windows): the result is the same either way.
constexpr std::size_t kParallelTiles = 32;

// Cells in a list below which a phase of run_cells runs on the calling thread.
constexpr std::size_t kParallelCells = 8192;

// touched_: a cell that gave or took less than SlopeRelaxOptions::settle (net).
constexpr std::uint8_t kSettled = 2;

}  // namespace

void SlopeRelaxWorkspace::fit(int width, int height) {
  if (width == width_ && height == height_) return;
  width_ = width, height_ = height;
  tiles_x_ = (width + kTile - 1) / kTile, tiles_y_ = (height + kTile - 1) / kTile;
  const std::size_t cells = static_cast<std::size_t>(width) * height;
  const std::size_t tiles = static_cast<std::size_t>(tiles_x_) * tiles_y_;
  take_.assign(cells, 0.0);
  slot_.assign(cells, 0);
  active_.assign(cells, 0), touched_.assign(cells, 0), ever_.assign(cells, 0);
  words_ = (width + 63) / 64;
  bits_.assign(static_cast<std::size_t>(words_) * height, 0);
  row_lo_.assign(static_cast<std::size_t>(height), std::numeric_limits<int>::max());
  row_hi_.assign(static_cast<std::size_t>(height), -1);
  tile_active_.assign(tiles, 0), tile_touched_.assign(tiles, 0);
  tile_ever_.assign(tiles, 0), tile_mark_.assign(tiles, 0);
}

// One relaxation call: the field, its rules and the phases of a pass.
class SlopeRelaxer {
 public:
  SlopeRelaxer(Grid<double>& heights, const SlopeCells& cells, const SlopeRelaxOptions& options,
               SlopeRelaxWorkspace& ws, Grid<float>* disturbed, const SlopePassFn& on_pass)
      : h_(heights.values()),
        cells_(cells),
        o_(options),
        ws_(ws),
        disturbed_(disturbed),
        on_pass_(on_pass),
        w_(heights.width()),
        hgt_(heights.height()) {
    for (int k = 0; k < 8; ++k) {
      distance_[k] = std::hypot(kNeighbours8[k].dx * o_.dx, kNeighbours8[k].dy * o_.dy);
      offset_[k] = static_cast<std::ptrdiff_t>(kNeighbours8[k].dy) * w_ + kNeighbours8[k].dx;
    }
  }

  void seed(int index) {
    ws_.active_[static_cast<std::size_t>(index)] = 1;
    ws_.tile_active_[tile_of(index % w_, index / w_)] = 1;
  }
  void seed_all() {
    std::fill(ws_.active_.begin(), ws_.active_.end(), 1);
    std::fill(ws_.tile_active_.begin(), ws_.tile_active_.end(), 1);
  }

  // Passes over 16 x 16 tiles (relax_slopes_everywhere): a pass works on the
  // active cells of the active tiles and on every cell of those tiles and their
  // neighbours.
  SlopeRelaxReport run() {
    SlopeRelaxReport report;
    std::vector<int> active = tiles_where(ws_.tile_active_);
    while (!active.empty() && report.passes < o_.max_passes) {
      ++report.passes;
      givers_.clear();
      for (int t : active)
        for_cells(t, [&](std::size_t i, int, int) {
          if (ws_.active_[i]) givers_.push_back(static_cast<int>(i));
        });
      near_ = with_neighbours(active);
      near_cells_.clear();
      for (int t : near_)
        for_cells(t, [&](std::size_t i, int, int) { near_cells_.push_back(static_cast<int>(i)); });
      report.moved += pass(givers_, near_cells_);
      for_each_item(near_, kParallelTiles, [&](int t) {
        bool any = false;
        for_cells(t, [&](std::size_t i, int, int) { any = any || ws_.touched_[i]; });
        ws_.tile_touched_[static_cast<std::size_t>(t)] = any;
      });
      active = next_active(active);
      if (on_pass_)
        on_pass_(report.passes, static_cast<double>(active.size()) / ws_.tile_active_.size());
    }
    report.converged = active.empty();
    for (int t : active) clear_active(t);  // stopped by max_passes
    return report;
  }

  // The same passes over lists of cells instead of tiles (paper 000, 3.5: only
  // the cells that need it, outward from the contact): a pass visits the
  // active cells and their neighbours, nothing else, so a rim a few cells wide
  // costs its own cells, not the 16 x 16 tiles about it. Same flows, same bits
  // as run(): both call pass().
  SlopeRelaxReport run_cells(const std::vector<int>& seeds, std::vector<int>& moved) {
    SlopeRelaxReport report;
    std::vector<int> active;
    gather(seeds, active, false);
    moved.clear();
    std::vector<int> touched, was_touched;
    bool same = false;  // the active cells are those of the last pass
    while (!active.empty() && report.passes < o_.max_passes) {
      ++report.passes;
      // Only the givers that give (factor > 0) and their neighbours can
      // change this pass: every other cell gives nothing and is offered
      // nothing that flows (a giver of factor 0 offers, but its flows are
      // 0), so the pass's flows and bits are those over all the active
      // cells' neighbours, for about a quarter fewer cells in the takers'
      // and changes' phases.
      give_all(active);
      offering_.clear();
      for (std::size_t s = 0; s < active.size(); ++s)
        if (ws_.slot_[static_cast<std::size_t>(active[s])] == static_cast<int>(s + 1) &&
            ws_.offers_[s + 1])
          offering_.push_back(active[s]);
      gather(offering_, near_cells_, true);
      report.moved += flow_all(active, near_cells_);
      // After a pass: a cell is active if it or a neighbour gave or took.
      // Only a cell whose height changed by more than `settle` keeps its
      // neighbours active (kSettled: it moved less); every cell that moved is
      // reported.
      touched.clear();
      for (int c : near_cells_) {
        const std::size_t i = static_cast<std::size_t>(c);
        const std::uint8_t t = ws_.touched_[i];
        if (!t) continue;
        ws_.touched_[i] = 0;
        if (!ws_.ever_[i]) ws_.ever_[i] = 1, moved.push_back(c);
        if (t != kSettled) touched.push_back(c);
      }
      // The slow tail of a slump moves the same cells pass after pass: then the
      // lists built from them are the same too (the same cells in the same
      // order, since each list is built from the one before).
      same = touched == was_touched;
      if (same) continue;  // the same active cells
      gather(touched, active, true);
      std::swap(touched, was_touched);
    }
    report.converged = active.empty();
    for (int c : moved) ws_.ever_[static_cast<std::size_t>(c)] = 0;
    std::sort(moved.begin(), moved.end());
    return report;
  }

  // The cells that gave or took in any pass, ascending; clears their marks.
  void collect_moved(std::vector<int>& out) {
    out.clear();
    for (int t : tiles_where(ws_.tile_ever_)) {
      ws_.tile_ever_[static_cast<std::size_t>(t)] = 0;
      for_cells(t, [&](std::size_t i, int, int) {
        if (ws_.ever_[i]) out.push_back(static_cast<int>(i)), ws_.ever_[i] = 0;
      });
    }
    std::sort(out.begin(), out.end());
  }

 private:
  // A flat index's column and row without an integer divide (tens of cycles,
  // several a cell a pass): the reciprocal's product is within one of the
  // row for any index of a grid that fits in memory, and is corrected exactly.
  std::pair<int, int> split(int c) const {
    int y = static_cast<int>(c * inv_w_);
    int x = c - y * w_;
    if (x < 0) x += w_, --y;
    if (x >= w_) x -= w_, ++y;
    return {x, y};
  }
  std::size_t tile_of(int x, int y) const {
    return static_cast<std::size_t>(y / kTile) * ws_.tiles_x_ + x / kTile;
  }
  template <class Fn>
  void for_cells(int tile, const Fn& fn) const {
    const int x0 = tile % ws_.tiles_x_ * kTile, y0 = tile / ws_.tiles_x_ * kTile;
    for (int y = y0; y < std::min(y0 + kTile, hgt_); ++y)
      for (int x = x0; x < std::min(x0 + kTile, w_); ++x)
        fn(static_cast<std::size_t>(y) * w_ + x, x, y);
  }
  std::vector<int> tiles_where(const std::vector<std::uint8_t>& flag) const {
    std::vector<int> out;
    for (std::size_t t = 0; t < flag.size(); ++t)
      if (flag[t]) out.push_back(static_cast<int>(t));
    return out;
  }
  // The tiles of `tiles` and their 8 neighbours, ascending.
  std::vector<int> with_neighbours(const std::vector<int>& tiles) {
    std::vector<int> out;
    for (int t : tiles) {
      const int tx = t % ws_.tiles_x_, ty = t / ws_.tiles_x_;
      for (int j = std::max(ty - 1, 0); j <= std::min(ty + 1, ws_.tiles_y_ - 1); ++j)
        for (int i = std::max(tx - 1, 0); i <= std::min(tx + 1, ws_.tiles_x_ - 1); ++i) {
          std::uint8_t& mark = ws_.tile_mark_[static_cast<std::size_t>(j) * ws_.tiles_x_ + i];
          if (!mark) mark = 1, out.push_back(j * ws_.tiles_x_ + i);
        }
    }
    for (int t : out) ws_.tile_mark_[static_cast<std::size_t>(t)] = 0;
    std::sort(out.begin(), out.end());
    return out;
  }

  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < w_ && y < hgt_; }
  // All 8 neighbours of (x, y) lie in the grid.
  bool interior(int x, int y) const { return x > 0 && y > 0 && x < w_ - 1 && y < hgt_ - 1; }
  // Neighbour k of cell (x, y) lies in the grid.
  bool has(int x, int y, int k) const {
    return inside(x + kNeighbours8[k].dx, y + kNeighbours8[k].dy);
  }
  const SlopeRule& rule_at(std::size_t i) const {
    return cells_.rule_of_cell ? cells_.rules[cells_.rule_of_cell->values()[i]] : cells_.rules[0];
  }
  double ceiling(std::size_t i) const {
    return cells_.ceiling ? cells_.ceiling->values()[i] : kInf;
  }
  double floor(std::size_t i) const {
    return std::max(cells_.floor ? cells_.floor->values()[i] : -kInf, cells_.min_value);
  }
  double surface(std::size_t i) const {
    return cells_.base ? static_cast<double>(cells_.base->values()[i]) + h_[i] : h_[i];
  }
  // Whether an active cell i may give this pass (its rule, its ceiling).
  bool giver(std::size_t i) const {
    return std::isfinite(rule_at(i).tan_repose) && h_[i] < ceiling(i);
  }

  // The tangent cell i slides at (SlopeRule::rough): a pure function of the
  // seed and the cell, so a cell keeps its angle from pass to pass and call to
  // call.
  double tan_of(std::size_t i, const SlopeRule& r) const {
    if (!r.rough) return r.tan_repose;
    std::uint64_t cell = i;
    if (o_.index_width > 0) {
      const auto [x, y] = split(static_cast<int>(i));
      cell =
          static_cast<std::uint64_t>((static_cast<std::int64_t>(y) + o_.index_y0) * o_.index_width +
                                     static_cast<std::int64_t>(x) + o_.index_x0);
    }
    return r.tan_repose * (1.0 - r.fraction * unit_double(mix64(seed_ ^ cell)));
  }

  // The per-pair rule, written once for both loops (tiles and cell lists) and
  // worked out once a pass per pair: the excess of the slope from giver i
  // (surface hi, its angle's tangent t) to its neighbour in direction k,
  // e = (H_i - H_n) - tan(theta) d_k. A pair counts when e > tolerance. Givers
  // keep their eight excesses for the pass (excess_, -inf outside the grid), so
  // the taker's share and both ends of every flow read the very same bits.
  double pair_excess(double hi, std::size_t n, double t, int k) const {
    return hi - surface(n) - t * distance_[k];
  }
  // What giver slot s offers for excess e (SlopeShare::Fraction: sigma e;
  // HalfSteepest: its factor times e) and what flows of it to a taker that
  // takes `take` of its offers: the offer times the giver's factor (Fraction;
  // HalfSteepest's post_ is 1, exact) times `take`.
  double offer(std::size_t s, double e) const { return ws_.mult_[s] * e; }
  double flow(std::size_t s, double e, double take) const {
    return offer(s, e) * ws_.post_[s] * take;
  }

  // Phase 1: giver i (slot s) works out its excesses and its factor: Fraction:
  // the scale keeping its flows within half its largest excess and its floor;
  // HalfSteepest: min(room, e_max / 2) / sum e.
  void give(std::size_t s, std::size_t i) {
    const auto [x, y] = split(static_cast<int>(i));
    const SlopeRule& r = rule_at(i);
    const double hi = surface(i), t = tan_of(i, r);
    double* e = &ws_.excess_[8 * s];
    if (interior(x, y) && !cells_.base) {
      // The common case in a register-friendly form: the same sums as
      // pair_excess, with the height field's data read once, not after every
      // store to e (the compiler cannot tell e does not alias the vector).
      const double* h = h_.data() + i;
      for (int k = 0; k < 8; ++k) e[k] = hi - h[offset_[k]] - t * distance_[k];
    } else if (interior(x, y)) {
      for (int k = 0; k < 8; ++k) e[k] = pair_excess(hi, i + offset_[k], t, k);
    } else {
      for (int k = 0; k < 8; ++k)
        e[k] = has(x, y, k) ? pair_excess(hi, i + offset_[k], t, k) : -kInf;
    }
    const double room = std::max(h_[i] - floor(i), 0.0);
    double sum = 0.0, largest = 0.0;
    const double share = r.share == SlopeShare::Fraction ? r.fraction : 1.0;
    // Branch-free (whether a pair counts is a coin toss for the predictor):
    // a pair that does not count adds +0.0, which leaves the sums' bits as
    // skipping it would.
    const double tolerance = o_.tolerance;
    for (int k = 0; k < 8; ++k) {
      const bool counts = e[k] > tolerance;
      sum += counts ? share * e[k] : 0.0;
      largest = std::max(largest, counts ? e[k] : 0.0);
    }
    double factor = 0.0;
    if (sum > 0.0) {
      // Paper 003: a film thinner than the tolerance is as good as bare (it
      // would trickle on for ever in amounts nobody can see).
      if (r.share == SlopeShare::HalfSteepest)
        factor = room > o_.tolerance ? std::min(room, 0.5 * largest) / sum : 0.0;
      else  // min(a / s, b / s) = min(a, b) / s: division by s > 0 is monotone, one divide
        factor = std::min(1.0, std::min(0.5 * largest, room) / sum);
    }
    ws_.factor_[s] = factor;
    ws_.offers_[s] = factor > 0.0;  // it gives: its neighbours may take
    ws_.mult_[s] = r.share == SlopeShare::Fraction ? r.fraction : factor;
    ws_.post_[s] = r.share == SlopeShare::Fraction ? factor : 1.0;
    ws_.slot_[i] = static_cast<int>(s);
  }
  // Giver slots start at 1: slot 0 (slot_'s "none") is a giver that offers
  // nothing (excesses -inf, factors 0), so the interior loops below read
  // every neighbour's slot without a branch.
  // Calls fn(s, e) for every giver (slot s) next to cell i with excess e
  // towards it.
  template <class Fn>
  void for_offers(std::size_t i, int x, int y, const Fn& fn) const {
    // The vectors' data once (the compiler cannot tell they do not alias h_).
    const int* slot = ws_.slot_.data();
    const double* excess = ws_.excess_.data();
    const double tolerance = o_.tolerance;
    const bool all = interior(x, y);
    for (int k = 0; k < 8; ++k) {
      if (!all && !has(x, y, k)) continue;
      const int s = slot[static_cast<std::ptrdiff_t>(i) + offset_[k]];
      if (s == 0) continue;
      const double e = excess[8 * static_cast<std::size_t>(s) + (7 - k)];
      if (e > tolerance) fn(static_cast<std::size_t>(s), e);
    }
  }
  // Phase 2: the share of its offers a taker takes (half the largest excess it is
  // offered from, its ceiling).
  double take_share(std::size_t i, int x, int y) const {
    double in = 0.0, largest = 0.0;
    if (interior(x, y)) {
      // for_offers without branches (slot 0 offers nothing; +0.0 for a pair
      // that does not count leaves the sums' bits as skipping it would).
      const int* slot = ws_.slot_.data() + i;
      const double* excess = ws_.excess_.data();
      const double* mult = ws_.mult_.data();
      const double tolerance = o_.tolerance;
      for (int k = 0; k < 8; ++k) {
        const auto s = static_cast<std::size_t>(slot[offset_[k]]);
        const double e = excess[8 * s + (7 - k)];
        const bool counts = e > tolerance;
        in += counts ? mult[s] * e : 0.0;
        largest = std::max(largest, counts ? e : 0.0);
      }
    } else {
      for_offers(i, x, y, [&](std::size_t s, double e) {
        in += offer(s, e);
        largest = std::max(largest, e);
      });
    }
    if (!(in > 0.0)) return 0.0;
    const double room = ceiling(i) - h_[i];
    // One divide: division by in > 0 is monotone (as in give).
    return std::min(1.0, std::min(0.5 * largest, std::max(room, 0.0)) / in);
  }
  // Phase 3: the change of cell i (taken - given), applied at once: nothing
  // in this phase reads a height (the excesses and shares are the pass's), so
  // the pass stays Jacobi. Returns what it gave.
  double change(std::size_t i, int x, int y) {
    double out = 0.0, in = 0.0;
    bool moved = false;
    // The disturbance is summed in a register and stored once: the same
    // float additions in the same order as adding to the cell each time, but
    // without a store-to-load chain through memory for every flow (the
    // compiler cannot tell the grid does not alias the workspace's vectors).
    float* disturbed = disturbed_ ? &disturbed_->values()[i] : nullptr;
    float dist = disturbed ? *disturbed : 0.0f;
    const int s = ws_.slot_[i];
    const double* take = ws_.take_.data();
    const double tolerance = o_.tolerance;
    // Branch-free like take_share: a flow that does not happen adds +0.0 (the
    // same bits as skipping it; the disturbance too, +0.0f).
    if (s > 0 && ws_.factor_[static_cast<std::size_t>(s)] > 0.0) {
      const double* e = &ws_.excess_[8 * static_cast<std::size_t>(s)];
      const double mult = ws_.mult_[static_cast<std::size_t>(s)];
      const double post = ws_.post_[static_cast<std::size_t>(s)];
      const bool all = interior(x, y);
      for (int k = 0; k < 8; ++k) {
        // Outside the grid e is -inf and the take is not read.
        const double t =
            all || e[k] > tolerance ? take[static_cast<std::ptrdiff_t>(i) + offset_[k]] : 0.0;
        const double f = mult * e[k] * post * t;
        const bool flows = e[k] > tolerance && f > 0.0;
        out += flows ? f : 0.0, moved = moved || flows;
        dist += flows ? static_cast<float>(f) : 0.0f;
      }
    }
    const double take_i = ws_.take_[i];
    if (take_i > 0.0 && interior(x, y)) {
      const int* slot = ws_.slot_.data() + i;
      const double* excess = ws_.excess_.data();
      const double* mult = ws_.mult_.data();
      const double* post = ws_.post_.data();
      for (int k = 0; k < 8; ++k) {
        const auto n = static_cast<std::size_t>(slot[offset_[k]]);
        const double e = excess[8 * n + (7 - k)];
        const double f = mult[n] * e * post[n] * take_i;
        const bool flows = e > tolerance && f > 0.0;
        in += flows ? f : 0.0, moved = moved || flows;
        dist += flows ? static_cast<float>(f) : 0.0f;
      }
    } else if (take_i > 0.0) {
      for_offers(i, x, y, [&](std::size_t n, double e) {
        const double f = flow(n, e, take_i);
        if (!(f > 0.0)) return;
        in += f, moved = true;
        dist += static_cast<float>(f);
      });
    }
    if (disturbed) *disturbed = dist;
    h_[i] += in - out;
    ws_.touched_[i] = !moved ? 0 : o_.settle > 0.0 && in + out <= o_.settle ? kSettled : 1;
    return out;
  }

  // One Jacobi pass: the cells of `active` that may give, and every cell of
  // `near` (the active cells and all their neighbours) takes; each phase is a
  // function of each cell alone, so the lists' order and the thread count do
  // not matter. Returns the height moved.
  double pass(const std::vector<int>& active, const std::vector<int>& near) {
    give_all(active);
    return flow_all(active, near);
  }
  // Phase 1 for every cell of `active` that may give (slot: its place + 1).
  void give_all(const std::vector<int>& active) {
    const std::size_t slots = active.size() + 1;  // slot 0: nobody
    if (ws_.excess_.size() < 8 * slots) {
      ws_.excess_.resize(8 * slots);
      ws_.mult_.resize(slots), ws_.post_.resize(slots), ws_.factor_.resize(slots);
      ws_.offers_.resize(slots);
      std::fill_n(ws_.excess_.begin(), 8, -kInf);
      ws_.mult_[0] = ws_.post_[0] = ws_.factor_[0] = 0.0;
    }
    for_each_index(active.size(), kParallelCells, [&](std::size_t s) {
      const auto i = static_cast<std::size_t>(active[s]);
      if (giver(i)) give(s + 1, i);
    });
  }
  // Phases 2 and 3 over `near` (every giver with an offer and its
  // neighbours, at least); clears the givers' slots. Returns the height moved.
  double flow_all(const std::vector<int>& active, const std::vector<int>& near) {
    for_each_cell(near, [&](std::size_t i, int x, int y) { ws_.take_[i] = take_share(i, x, y); });
    gave_.assign(near.size(), 0.0);
    for_each_index(near.size(), kParallelCells, [&](std::size_t k) {
      const int c = near[k];
      const auto [x, y] = split(c);
      gave_[k] = change(static_cast<std::size_t>(c), x, y);
    });
    for (int c : active) ws_.slot_[static_cast<std::size_t>(c)] = 0;
    double moved = 0.0;
    for (double g : gave_) moved += g;
    return moved;
  }

  // Cell lists (run_cells) as a bitmap, a bit a cell: `out` gets the cells of
  // `cells` (with `dilate`, and their 8 neighbours), each once, in ascending
  // order, a word of 64 cells at a time. Ascending lists make every phase
  // walk the grid row by row (neighbours' heights, slots and shares in the
  // cache lines just used, givers' excesses in slot order): 40 % less time in
  // the phases than lists in the order first met, for the same flows (a pass
  // is Jacobi: the order of its cells does not change a bit). The bitmap and
  // the rows' word ranges are cleared again before returning.
  void gather(const std::vector<int>& cells, std::vector<int>& out, bool dilate) {
    out.clear();
    if (cells.empty()) return;
    const int words = ws_.words_;
    std::uint64_t* bits = ws_.bits_.data();
    int* lo = ws_.row_lo_.data();
    int* hi = ws_.row_hi_.data();
    rows_.clear();
    for (int c : cells) {
      const auto [x, y] = split(c);
      const int wx = x >> 6;
      bits[static_cast<std::size_t>(y) * words + wx] |= std::uint64_t{1} << (x & 63);
      if (hi[y] < 0) rows_.push_back(y);
      lo[y] = std::min(lo[y], wx), hi[y] = std::max(hi[y], wx);
    }
    std::sort(rows_.begin(), rows_.end());
    const int tail = w_ - 64 * (words - 1);  // cells in a row's last word
    const std::uint64_t last_mask = tail == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << tail) - 1;
    auto emit = [&](int y, int wx, std::uint64_t v) {
      const int base = y * w_ + 64 * wx;
      while (v) {
        out.push_back(base + std::countr_zero(v));
        v &= v - 1;
      }
    };
    if (!dilate) {
      for (int y : rows_)
        for (int wx = lo[y]; wx <= hi[y]; ++wx)
          emit(y, wx, bits[static_cast<std::size_t>(y) * words + wx]);
    } else {
      // Row y of the dilation: the rows y - 1, y, y + 1 or-ed, then spread a
      // cell left and right (carrying across words).
      auto column = [&](int y, int wx) {
        std::uint64_t v = 0;
        for (int r = std::max(y - 1, 0); r <= std::min(y + 1, hgt_ - 1); ++r)
          v |= bits[static_cast<std::size_t>(r) * words + wx];
        return v;
      };
      int done = -1;  // the last output row
      for (int r : rows_)
        for (int y = std::max(r - 1, std::max(done + 1, 0)); y <= std::min(r + 1, hgt_ - 1); ++y) {
          int a = std::numeric_limits<int>::max(), b = -1;
          for (int q = std::max(y - 1, 0); q <= std::min(y + 1, hgt_ - 1); ++q)
            if (hi[q] >= 0) a = std::min(a, lo[q]), b = std::max(b, hi[q]);
          a = std::max(a - 1, 0), b = std::min(b + 1, words - 1);
          std::uint64_t left = a > 0 ? column(y, a - 1) : 0, mid = column(y, a);
          for (int wx = a; wx <= b; ++wx) {
            const std::uint64_t right = wx + 1 < words ? column(y, wx + 1) : 0;
            std::uint64_t v = mid | (mid << 1) | (left >> 63) | (mid >> 1) | (right << 63);
            if (wx == words - 1) v &= last_mask;
            emit(y, wx, v);
            left = mid, mid = right;
          }
          done = y;
        }
    }
    for (int y : rows_) {
      std::fill_n(bits + static_cast<std::size_t>(y) * words + lo[y], hi[y] - lo[y] + 1, 0);
      lo[y] = std::numeric_limits<int>::max(), hi[y] = -1;
    }
  }
  template <class Fn>
  void for_each_cell(const std::vector<int>& cells, const Fn& fn) const {
    for_each_index(cells.size(), kParallelCells, [&](std::size_t k) {
      const int c = cells[k];
      const auto [x, y] = split(c);
      fn(static_cast<std::size_t>(c), x, y);
    });
  }

  void clear_active(int t) {
    for_cells(t, [&](std::size_t i, int, int) { ws_.active_[i] = 0; });
    ws_.tile_active_[static_cast<std::size_t>(t)] = 0;
  }
  // After a pass: a cell is active if it or a neighbour gave or took. Returns the
  // tiles with active cells and clears the pass's marks.
  std::vector<int> next_active(const std::vector<int>& was_active) {
    std::vector<int> touched;
    for (int t : near_)
      if (ws_.tile_touched_[static_cast<std::size_t>(t)]) touched.push_back(t);
    std::vector<int> candidates = with_neighbours(touched);
    for (int t : was_active) ws_.tile_mark_[static_cast<std::size_t>(t)] = 1;
    for (int t : candidates) ws_.tile_mark_[static_cast<std::size_t>(t)] = 0;
    for (int t : was_active)  // active before, not a candidate now: clear
      if (ws_.tile_mark_[static_cast<std::size_t>(t)]) clear_active(t);
    for (int t : was_active) ws_.tile_mark_[static_cast<std::size_t>(t)] = 0;
    for_each_item(candidates, kParallelTiles, [&](int t) { mark_active(t); });
    for_each_item(touched, kParallelTiles, [&](int t) {
      ws_.tile_ever_[static_cast<std::size_t>(t)] = 1;
      for_cells(t, [&](std::size_t i, int, int) { ws_.ever_[i] |= ws_.touched_[i]; });
    });
    for_each_item(touched, kParallelTiles, [&](int t) {
      for_cells(t, [&](std::size_t i, int, int) { ws_.touched_[i] = 0; });
      ws_.tile_touched_[static_cast<std::size_t>(t)] = 0;
    });
    std::vector<int> next;
    for (int t : candidates)
      if (ws_.tile_active_[static_cast<std::size_t>(t)]) next.push_back(t);
    return next;
  }
  void mark_active(int t) {
    bool any = false;
    for_cells(t, [&](std::size_t i, int x, int y) {
      bool a = ws_.touched_[i] != 0;
      for (int k = 0; k < 8 && !a; ++k) a = has(x, y, k) && ws_.touched_[i + offset_[k]];
      ws_.active_[i] = a;
      any = any || a;
    });
    ws_.tile_active_[static_cast<std::size_t>(t)] = any;
  }

  std::vector<double>& h_;
  const SlopeCells& cells_;
  const SlopeRelaxOptions& o_;
  SlopeRelaxWorkspace& ws_;
  Grid<float>* disturbed_;
  const SlopePassFn& on_pass_;
  int w_, hgt_;
  double inv_w_ = 1.0 / w_;
  std::array<double, 8> distance_{};
  std::uint64_t seed_ = mix64(o_.seed);     // the roughness draws' (tan_of)
  std::array<std::ptrdiff_t, 8> offset_{};  // flat index of neighbour k - the cell's
  std::vector<int> near_;                   // run(): this pass's active tiles and their neighbours
  std::vector<int> givers_;                 // run(): this pass's active cells
  std::vector<int> near_cells_;             // this pass's active cells and their neighbours
  std::vector<double> gave_;                // per cell of near_cells_
  std::vector<int> rows_;                   // gather(): the rows with cells
  std::vector<int> offering_;               // run_cells(): this pass's givers with an offer
};

SlopeRelaxReport relax_slopes(Grid<double>& heights, const std::vector<int>& active,
                              const SlopeCells& cells, const SlopeRelaxOptions& options,
                              std::vector<int>& moved_cells, Grid<float>* disturbed,
                              SlopeRelaxWorkspace* workspace) {
  SlopeRelaxWorkspace local;
  SlopeRelaxWorkspace& ws = workspace ? *workspace : local;
  ws.fit(heights.width(), heights.height());
  const SlopePassFn none;
  SlopeRelaxer relaxer(heights, cells, options, ws, disturbed, none);
  return relaxer.run_cells(active, moved_cells);
}

SlopeRelaxReport relax_slopes_everywhere(Grid<double>& heights, const SlopeCells& cells,
                                         const SlopeRelaxOptions& options,
                                         SlopeRelaxWorkspace* workspace,
                                         const SlopePassFn& on_pass) {
  SlopeRelaxWorkspace local;
  SlopeRelaxWorkspace& ws = workspace ? *workspace : local;
  ws.fit(heights.width(), heights.height());
  SlopeRelaxer relaxer(heights, cells, options, ws, nullptr, on_pass);
  relaxer.seed_all();
  const SlopeRelaxReport report = relaxer.run();
  std::vector<int> unused;
  relaxer.collect_moved(unused);
  return report;
}

double max_slope_excess(const Grid<double>& heights, const SlopeCells& cells,
                        const SlopeRelaxOptions& options, std::span<const int> only,
                        double min_room) {
  const int w = heights.width(), hgt = heights.height();
  const auto& h = heights.values();
  auto surface = [&](std::size_t i) {
    return cells.base ? static_cast<double>(cells.base->values()[i]) + h[i] : h[i];
  };
  double worst = 0.0;
  auto visit = [&](int index) {
    const std::size_t i = static_cast<std::size_t>(index);
    const SlopeRule& rule =
        cells.rule_of_cell ? cells.rules[cells.rule_of_cell->values()[i]] : cells.rules[0];
    if (!std::isfinite(rule.tan_repose)) return;
    const double floor = std::max(cells.floor ? cells.floor->values()[i] : -kInf, cells.min_value);
    if (!(h[i] - floor > min_room)) return;
    const int x = index % w, y = index / w;
    for (const NeighbourOffset& nb : kNeighbours8) {
      const int nx = x + nb.dx, ny = y + nb.dy;
      if (nx < 0 || ny < 0 || nx >= w || ny >= hgt) continue;
      const std::size_t n = static_cast<std::size_t>(ny) * w + nx;
      if (cells.ceiling && std::isfinite(cells.ceiling->values()[n])) continue;
      const double d = std::hypot(nb.dx * options.dx, nb.dy * options.dy);
      worst = std::max(worst, surface(i) - surface(n) - rule.tan_repose * d);
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
