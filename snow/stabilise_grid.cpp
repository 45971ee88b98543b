#include "snow/stabilise_grid.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "snow/stabilise_levels.h"
#include "snow/stabilise_settle.h"
#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/slope_relax.h"

namespace drift::snow {

namespace {

// Cells per tile side: small tiles follow the moving snow closely (16 did a
// quarter more work at 1024^2, where a third of an active 16 x 16 tile's cells
// are active).
constexpr int kTile = 4;
// The active share that decides when the passes are in their tail is counted
// on blocks of this many cells a side (a multiple of kTile), whatever kTile is,
// so that the shortcut runs when it always has.
constexpr int kShareBlock = 16;
static_assert(kShareBlock % kTile == 0);
// Tiles below which a phase runs on the calling thread (same result either way).
constexpr std::size_t kParallelTiles = 32;
// The shortcut (snow/stabilise_settle.h) runs once the passes are in their
// slow tail: at least kTailPasses passes since the start or the last shortcut,
// and fewer than kTailShare of the tiles still active.
constexpr int kTailPasses = 200;
constexpr double kTailShare = 0.1;
// The coarse-to-fine start stops before a level of fewer cells a side.
constexpr int kCoarsestCells = 32;
// Neighbour k and neighbour 7 - k are opposite (the order of terrain/slope_relax,
// so that sums are formed in the same order and give the same bits).
constexpr std::array<int, 8> kDx{-1, 0, 1, -1, 1, -1, 0, 1};
constexpr std::array<int, 8> kDy{-1, -1, -1, 0, 0, 1, 1, 1};

double tan_deg(double deg) { return std::tan(deg * std::numbers::pi / 180.0); }

template <class Fn>
void for_list(const std::vector<int>& items, const Fn& fn) {
  if (items.size() < kParallelTiles) {
    for (int t : items) fn(t);
    return;
  }
  tbb::parallel_for(std::size_t{0}, items.size(), [&](std::size_t k) { fn(items[k]); });
}

// The HalfSteepest passes of terrain/slope_relax, specialised for snow on
// ground (one rule, floor 0, no ceiling) and written for speed: the snow surface
// is kept as one array, inner cells skip the edge tests and the repose drop to
// each neighbour is computed once. Every operation and its order are those of
// terrain/slope_relax, so the result is the same to the bit.
class SnowPasses {
 public:
  SnowPasses(const terrain::Grid<float>& ground, terrain::Grid<double>& snow, double dx, double dy,
             double tan_repose, double tolerance)
      : g_(ground.values().data()),
        h_(snow.values().data()),
        w_(snow.width()),
        hgt_(snow.height()),
        tol_(tolerance) {
    for (int k = 0; k < 8; ++k) {
      drop_[k] = tan_repose * std::hypot(kDx[k] * dx, kDy[k] * dy);
      offset_[k] = static_cast<std::ptrdiff_t>(kDy[k]) * w_ + kDx[k];
    }
    tiles_x_ = (w_ + kTile - 1) / kTile, tiles_y_ = (hgt_ + kTile - 1) / kTile;
    const std::size_t cells = static_cast<std::size_t>(w_) * hgt_;
    surface_.resize(cells);
    for (std::size_t i = 0; i < cells; ++i) surface_[i] = static_cast<double>(g_[i]) + h_[i];
    give_.assign(cells, 0.0), take_.assign(cells, 0.0), delta_.assign(cells, 0.0);
    active_.assign(cells, 0), touched_.assign(cells, 0);
    const std::size_t tiles = static_cast<std::size_t>(tiles_x_) * tiles_y_;
    tile_active_.assign(tiles, 0), tile_touched_.assign(tiles, 0), tile_mark_.assign(tiles, 0);
    blocks_x_ = (w_ + kShareBlock - 1) / kShareBlock;
    block_mark_.assign(
        static_cast<std::size_t>(blocks_x_) * ((hgt_ + kShareBlock - 1) / kShareBlock), 0);
    for (std::size_t i = 0; i < cells; ++i) activate(i);
    active_tiles_ = tiles_where_active();
  }

  // Bytes a grid of `cells` needs on top of the snow and the ground.
  static std::uint64_t bytes_per_cell() { return 4 * sizeof(double) + 2; }

  // Passes until nothing moves, max_passes, or pause(passes, active share)
  // says to stop for now (it is also the progress report); true if converged.
  template <class Pause>
  bool run(int max_passes, const Pause& pause) {
    while (!active_tiles_.empty() && passes_ < max_passes) {
      ++passes_;
      pass(active_tiles_);
      active_tiles_ = next_active(active_tiles_);
      const double share = active_share();
      if (pause(passes_, share)) break;
    }
    return active_tiles_.empty();
  }
  int passes() const { return passes_; }
  // After the snow of `cells` was changed from outside: they and their
  // neighbours look again.
  void changed(const std::vector<std::size_t>& cells) {
    for (std::size_t i : cells) {
      surface_[i] = static_cast<double>(g_[i]) + h_[i];
      activate(i);
      for (int k = 0; k < 8; ++k)
        if (inside(i, k)) activate(i + offset_[k]);
    }
    active_tiles_ = tiles_where_active();
  }

 private:
  // The share of the kShareBlock-sized blocks holding an active cell.
  double active_share() {
    constexpr int per = kShareBlock / kTile;
    std::size_t count = 0;
    for (int t : active_tiles_) {
      std::uint8_t& mark = block_mark_[static_cast<std::size_t>(t / tiles_x_ / per) * blocks_x_ +
                                       t % tiles_x_ / per];
      count += mark == 0, mark = 1;
    }
    for (int t : active_tiles_)
      block_mark_[static_cast<std::size_t>(t / tiles_x_ / per) * blocks_x_ + t % tiles_x_ / per] =
          0;
    return static_cast<double>(count) / block_mark_.size();
  }
  // Calls fn(i, edge) for the cells of a tile; edge: a neighbour may be outside.
  template <class Fn>
  void for_cells(int tile, const Fn& fn) const {
    const int x0 = tile % tiles_x_ * kTile, y0 = tile / tiles_x_ * kTile;
    const int x1 = std::min(x0 + kTile, w_), y1 = std::min(y0 + kTile, hgt_);
    for (int y = y0; y < y1; ++y) {
      const bool edge_row = y == 0 || y == hgt_ - 1;
      for (int x = x0; x < x1; ++x)
        fn(static_cast<std::size_t>(y) * w_ + x, edge_row || x == 0 || x == w_ - 1);
    }
  }
  bool inside(std::size_t i, int k) const {
    const int x = static_cast<int>(i % w_) + kDx[k], y = static_cast<int>(i / w_) + kDy[k];
    return x >= 0 && y >= 0 && x < w_ && y < hgt_;
  }
  // Excess of the slope from cell i down to its neighbour n in direction k.
  double excess(std::size_t i, std::size_t n, int k) const {
    return surface_[i] - surface_[n] - drop_[k];
  }

  // Phase 1, paper 003 2.1(3): a giver gives min(held, e_max / 2), shared among
  // its steeper neighbours in proportion to their excess; the factor per excess.
  double give_factor(std::size_t i, bool edge) const {
    double sum = 0.0, largest = 0.0;
    for (int k = 0; k < 8; ++k) {
      if (edge && !inside(i, k)) continue;
      // Adding 0.0 to a sum of positive terms leaves its bits: the same
      // result as skipping, without a branch the data cannot predict.
      const double e = excess(i, i + offset_[k], k);
      const double over = e > tol_ ? e : 0.0;
      sum += over;
      largest = std::max(largest, over);
    }
    if (sum <= 0.0) return 0.0;
    const double room = std::max(h_[i] - 0.0, 0.0);
    return room > tol_ ? std::min(room, 0.5 * largest) / sum : 0.0;
  }
  // Calls f(n, e, offered) for each neighbour n of cell i, e the excess of its
  // slope towards i, offered if n is active and e above the tolerance: the
  // offers i may take from, in the fixed neighbour order. f adds 0.0 where
  // nothing is offered (the same bits as skipping, without branches).
  template <class F>
  void for_each_offer_to(std::size_t i, bool edge, F&& f) const {
    for (int k = 0; k < 8; ++k) {
      if (edge && !inside(i, k)) continue;
      const std::size_t n = i + offset_[k];
      const double e = excess(n, i, 7 - k);
      f(n, e, active_[n] && e > tol_);
    }
  }
  // Phase 2: the share of its offers a taker takes (half the largest excess it
  // is offered from).
  double take_share(std::size_t i, bool edge) const {
    double in = 0.0, largest = 0.0;
    for_each_offer_to(i, edge, [&](std::size_t n, double e, bool offered) {
      in += offered ? give_[n] * e : 0.0;
      largest = std::max(largest, offered ? e : 0.0);
    });
    if (!(in > 0.0)) return 0.0;
    return std::min(1.0, 0.5 * largest / in);
  }
  // Phase 3: the change of cell i, taken - given; marks it touched if it moved.
  void change(std::size_t i, bool edge) {
    double out = 0.0, in = 0.0;
    bool moved = false;
    if (give_[i] > 0.0 && active_[i])
      for (int k = 0; k < 8; ++k) {
        if (edge && !inside(i, k)) continue;
        const std::size_t n = i + offset_[k];
        const double e = excess(i, n, k);
        const double f = e > tol_ ? give_[i] * e * take_[n] : 0.0;
        out += f, moved = moved || f > 0.0;
      }
    if (take_[i] > 0.0)
      for_each_offer_to(i, edge, [&](std::size_t n, double e, bool offered) {
        const double f = offered ? give_[n] * e * take_[i] : 0.0;
        in += f, moved = moved || f > 0.0;
      });
    delta_[i] = in - out;
    touched_[i] = moved;
  }

  // One Jacobi pass: every flow from the state before it.
  void pass(const std::vector<int>& active) {
    for_list(active, [&](int t) {
      for_cells(t, [&](std::size_t i, bool edge) {
        if (active_[i]) give_[i] = give_factor(i, edge);
      });
    });
    near_ = with_neighbours(active);
    for_list(near_, [&](int t) {
      for_cells(t, [&](std::size_t i, bool edge) { take_[i] = take_share(i, edge); });
    });
    for_list(near_, [&](int t) {
      bool any = false;
      for_cells(t, [&](std::size_t i, bool edge) {
        change(i, edge);
        any = any || touched_[i];
      });
      tile_touched_[static_cast<std::size_t>(t)] = any;
    });
    // give_, take_ and delta_ need no clearing: every pass writes them for
    // every cell it reads them at (active cells, and the tiles near them).
    for_list(near_, [&](int t) {
      for_cells(t, [&](std::size_t i, bool) {
        if (delta_[i] == 0.0) return;
        h_[i] += delta_[i];
        surface_[i] = static_cast<double>(g_[i]) + h_[i];
      });
    });
  }

  // The tiles of `tiles` and their 8 neighbours, ascending.
  std::vector<int> with_neighbours(const std::vector<int>& tiles) {
    std::vector<int> out;
    for (int t : tiles) {
      const int tx = t % tiles_x_, ty = t / tiles_x_;
      for (int j = std::max(ty - 1, 0); j <= std::min(ty + 1, tiles_y_ - 1); ++j)
        for (int i = std::max(tx - 1, 0); i <= std::min(tx + 1, tiles_x_ - 1); ++i) {
          std::uint8_t& mark = tile_mark_[static_cast<std::size_t>(j) * tiles_x_ + i];
          if (!mark) mark = 1, out.push_back(j * tiles_x_ + i);
        }
    }
    for (int t : out) tile_mark_[static_cast<std::size_t>(t)] = 0;
    std::sort(out.begin(), out.end());
    return out;
  }
  void activate(std::size_t i) {
    active_[i] = 1;
    const int x = static_cast<int>(i % w_), y = static_cast<int>(i / w_);
    tile_active_[static_cast<std::size_t>(y / kTile) * tiles_x_ + x / kTile] = 1;
  }
  std::vector<int> tiles_where_active() const {
    std::vector<int> out;
    for (std::size_t t = 0; t < tile_active_.size(); ++t)
      if (tile_active_[t]) out.push_back(static_cast<int>(t));
    return out;
  }
  void clear_active(int t) {
    for_cells(t, [&](std::size_t i, bool) { active_[i] = 0; });
    tile_active_[static_cast<std::size_t>(t)] = 0;
  }
  // A cell is active next pass if it or a neighbour gave or took in this one.
  void mark_active(int t) {
    bool any = false;
    for_cells(t, [&](std::size_t i, bool edge) {
      bool a = touched_[i] != 0;
      for (int k = 0; k < 8 && !a; ++k) a = (!edge || inside(i, k)) && touched_[i + offset_[k]];
      active_[i] = a;
      any = any || a;
    });
    tile_active_[static_cast<std::size_t>(t)] = any;
  }
  // The tiles with active cells after a pass; clears the pass's marks.
  std::vector<int> next_active(const std::vector<int>& was_active) {
    std::vector<int> touched;
    for (int t : near_)
      if (tile_touched_[static_cast<std::size_t>(t)]) touched.push_back(t);
    const std::vector<int> candidates = with_neighbours(touched);
    for (int t : candidates) tile_mark_[static_cast<std::size_t>(t)] = 1;
    for (int t : was_active)
      if (!tile_mark_[static_cast<std::size_t>(t)]) clear_active(t);
    for (int t : candidates) tile_mark_[static_cast<std::size_t>(t)] = 0;
    for_list(candidates, [&](int t) { mark_active(t); });
    for_list(touched, [&](int t) {
      for_cells(t, [&](std::size_t i, bool) { touched_[i] = 0; });
      tile_touched_[static_cast<std::size_t>(t)] = 0;
    });
    std::vector<int> next;
    for (int t : candidates)
      if (tile_active_[static_cast<std::size_t>(t)]) next.push_back(t);
    return next;
  }

  const float* g_;
  double* h_;
  int w_, hgt_, tiles_x_ = 0, tiles_y_ = 0;
  double tol_;
  std::array<double, 8> drop_{};
  std::array<std::ptrdiff_t, 8> offset_{};
  std::vector<double> surface_, give_, take_, delta_;
  std::vector<std::uint8_t> active_, touched_;
  std::vector<std::uint8_t> tile_active_, tile_touched_, tile_mark_;
  int blocks_x_ = 0;
  std::vector<std::uint8_t> block_mark_;  // active_share's scratch
  std::vector<int> active_tiles_;
  int passes_ = 0;
  std::vector<int> near_;  // this pass: active tiles and their neighbours
};

// Passes, and the shortcut each time they reach their slow tail, until they
// converge (the shortcut only moves snow; convergence is the passes' verdict).
template <class OnPass>
StabiliseReport settle(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                       const SettleGeometry& geo, int max_passes, bool shortcut,
                       const OnPass& on_pass) {
  SnowPasses passes(ground, snow, geo.dx, geo.dy, geo.tan_repose, geo.tolerance);
  int last = 0;
  auto pause = [&](int p, double share) {
    on_pass(p, share);
    return shortcut && p - last >= kTailPasses && share < kTailShare;
  };
  bool converged = false;
  while (!(converged = passes.run(max_passes, pause)) && passes.passes() < max_passes) {
    const auto changed = settle_unsupported(ground, snow, geo);
    shortcut = !changed.empty();
    last = passes.passes();
    passes.changed(changed);
  }
  StabiliseReport report;
  report.iterations = passes.passes();
  report.converged = converged;
  report.level_passes = {report.iterations};
  return report;
}

// The coarse-to-fine start (snow/stabilise_levels.h): `levels` coarser levels
// (fewer where the grid gets smaller than kCoarsestCells a side) settled first,
// coarsest first, each one's change handed down as the next one's start; then
// this level's passes to convergence.
template <class OnPass>
StabiliseReport settle_levels(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                              const SettleGeometry& geo, const StabiliseOptions& options,
                              int levels, const OnPass& on_pass) {
  std::vector<int> level_passes;
  if (levels > 0 && std::min(snow.width(), snow.height()) / 2 >= kCoarsestCells) {
    CoarseLevel coarse = restrict_to_coarse(ground, snow);
    const terrain::Grid<double> before = coarse.snow;
    SettleGeometry coarse_geo = geo;
    coarse_geo.dx *= 2.0, coarse_geo.dy *= 2.0;
    level_passes =
        settle_levels(coarse.ground, coarse.snow, coarse_geo, options, levels - 1, on_pass)
            .level_passes;
    prolong_change(coarse.ground, before, coarse.snow, snow);
  }
  StabiliseReport report =
      settle(ground, snow, geo, options.max_iterations, options.shortcut, on_pass);
  level_passes.push_back(report.iterations);
  report.level_passes = std::move(level_passes);
  return report;
}

}  // namespace

StabiliseReport stabilise_grid(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                               double dx, double dy, const StabiliseOptions& options,
                               const ProgressFn& progress) {
  if (!(options.repose_deg > 0.0 && options.repose_deg < 90.0))
    throw Error("the angle of repose of snow must lie in (0, 90) degrees");
  if (ground.width() != snow.width() || ground.height() != snow.height())
    throw Error("stabilise_grid: the ground and the snow grids differ in size");
  // The passes' workspace, and the shortcut's: envelope, loose snow, resting
  // cell and load (doubles and indices), marks, and a queue entry a cell at worst.
  const std::uint64_t shortcut_bytes = 4 * sizeof(double) + 1 + 16;
  // The coarse levels' grids (ground, snow, its copy and change: 28 bytes a
  // coarse cell, 7 a fine one; the levels below a quarter of that) are freed
  // before the finer level's workspace is made; counted on top as a margin.
  const std::uint64_t coarse_bytes = options.coarse_levels > 0 ? 10 : 0;
  require_memory(snow.size() * (SnowPasses::bytes_per_cell() + shortcut_bytes + coarse_bytes),
                 "snow stabilisation's workspace", "use a smaller or coarser ground raster");
  const SettleGeometry geo{dx, dy, tan_deg(options.repose_deg), options.tolerance};
  if (options.coarse_levels < 0)
    throw Error("stabilise_grid: the number of coarse levels must be 0 or more");
  StabiliseReport report =
      settle_levels(ground, snow, geo, options, options.coarse_levels, [&](int, double share) {
        if (!progress(1.0 - share, "stabilising snow")) throw Cancelled();
      });
  progress(1.0, "stabilising snow");
  return report;
}

double max_repose_excess(const terrain::Grid<float>& ground, const terrain::Grid<double>& snow,
                         double dx, double dy, double repose_deg, double min_snow) {
  const terrain::SlopeRule rule{tan_deg(repose_deg), 0.5, terrain::SlopeShare::HalfSteepest};
  terrain::SlopeCells cells{{&rule, 1}};
  cells.base = &ground;
  cells.min_value = 0.0;
  return terrain::max_slope_excess(snow, cells, {dx, dy}, {}, min_snow);
}

}  // namespace drift::snow
