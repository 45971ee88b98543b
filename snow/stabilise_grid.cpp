#include "snow/stabilise_grid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <type_traits>
#include <utility>
#include <vector>

#include "snow/stabilise_cells.h"
#include "snow/stabilise_direct.h"
#include "snow/stabilise_levels.h"
#include "snow/stabilise_settle.h"
#include "terrain/angles.h"
#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/neighbours.h"
#include "terrain/parallel.h"
#include "terrain/slope_relax.h"

namespace drift::snow {

namespace {

using kernel::kNotGiving;
using kernel::PassCells;
using kernel::Phase;
using kernel::row_kernel;
using kernel::RowKernel;

// Cells per tile side: small tiles follow the moving snow closely (16 did a
// quarter more work at 1024^2, where a third of an active 16 x 16 tile's cells
// are active).
constexpr int kTile = 4;  // (any_in_tile reads a tile's row as a 32-bit word)
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
using terrain::kNeighbours8;

// A run of consecutive tiles in one row of tiles (tx0 <= tile x < tx1). The
// phases work on runs, so that their inner loops run along rows of cells and
// the cells with all 8 neighbours inside take a path without edge tests that
// does several cells at once.
struct TileRun {
  int ty, tx0, tx1;
};

// The runs of an ascending list of tiles.
std::vector<TileRun> runs_of(const std::vector<int>& tiles, int tiles_x) {
  std::vector<TileRun> runs;
  int row_start = 0;  // the first tile of the last run's row of tiles
  for (int t : tiles) {
    if (!runs.empty() && t == row_start + runs.back().tx1 && runs.back().tx1 < tiles_x) {
      ++runs.back().tx1;
      continue;
    }
    const int ty = t / tiles_x;
    row_start = ty * tiles_x;
    runs.push_back({ty, t - row_start, t - row_start + 1});
  }
  return runs;
}

// Calls fn(run) for every run, in parallel when they hold many tiles (the
// same result either way: each cell's values are its own).
template <class Fn>
void for_runs(const std::vector<TileRun>& runs, std::size_t tiles, const Fn& fn) {
  const bool parallel = tiles >= kParallelTiles && runs.size() >= 2;
  terrain::for_each_item(runs, parallel ? 0 : runs.size() + 1, fn);
}

// Jacobi passes of terrain/slope_relax's HalfSteepest rule for snow on ground,
// written for speed (see PassCells): the snow surface is kept as one array,
// only the 4 x 4 tiles near what moved are visited, as runs along rows of
// tiles.
class SnowPasses {
 public:
  SnowPasses(const terrain::Grid<float>& ground, terrain::Grid<double>& snow, double dx, double dy,
             double tan_repose, double tolerance)
      : w_(snow.width()), hgt_(snow.height()) {
    tiles_x_ = (w_ + kTile - 1) / kTile, tiles_y_ = (hgt_ + kTile - 1) / kTile;
    const std::size_t cells = static_cast<std::size_t>(w_) * hgt_;
    surface_.resize(cells);
    for (std::size_t i = 0; i < cells; ++i)
      surface_[i] = static_cast<double>(ground.values()[i]) + snow.values()[i];
    give_.assign(cells, kNotGiving), take_.assign(cells, 0.0), delta_.assign(cells, 0.0);
    active_.assign(cells, 1), touched_.assign(cells, 0);
    c_ = {ground.values().data(),
          snow.values().data(),
          surface_.data(),
          give_.data(),
          take_.data(),
          delta_.data(),
          active_.data(),
          touched_.data(),
          {},
          {},
          tolerance};
    for (int k = 0; k < 8; ++k) {
      c_.drop[k] = tan_repose * std::hypot(kNeighbours8[k].dx * dx, kNeighbours8[k].dy * dy);
      c_.offset[k] = static_cast<std::ptrdiff_t>(kNeighbours8[k].dy) * w_ + kNeighbours8[k].dx;
    }
    const std::size_t tiles = static_cast<std::size_t>(tiles_x_) * tiles_y_;
    tile_active_.assign(tiles, 1), tile_touched_.assign(tiles, 0), tile_mark_.assign(tiles, 0);
    blocks_x_ = (w_ + kShareBlock - 1) / kShareBlock;
    block_mark_.assign(
        static_cast<std::size_t>(blocks_x_) * ((hgt_ + kShareBlock - 1) / kShareBlock), 0);
    set_active_tiles(tiles_where_active());
  }

  // Bytes a grid of `cells` needs on top of the snow and the ground.
  static std::uint64_t bytes_per_cell() { return 4 * sizeof(double) + 2; }

  // Passes until nothing moves, max_passes, or pause(passes, active share)
  // says to stop for now (it is also the progress report); true if converged.
  template <class Pause>
  bool run(int max_passes, const Pause& pause) {
    while (!active_tiles_.empty() && passes_ < max_passes) {
      ++passes_;
      pass();
      set_active_tiles(next_active(active_tiles_));
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
      surface_[i] = static_cast<double>(c_.ground[i]) + c_.snow[i];
      const int x = static_cast<int>(i % w_), y = static_cast<int>(i / w_);
      for (int j = std::max(y - 1, 0); j <= std::min(y + 1, hgt_ - 1); ++j)
        for (int k = std::max(x - 1, 0); k <= std::min(x + 1, w_ - 1); ++k) activate(k, j);
    }
    set_active_tiles(tiles_where_active());
  }

 private:
  // The share of the kShareBlock-sized blocks holding an active cell.
  double active_share() {
    constexpr int per = kShareBlock / kTile;
    std::size_t count = 0;
    const auto marks = [&](std::uint8_t value) {
      for (const TileRun& r : active_runs_) {
        std::uint8_t* row = block_mark_.data() + static_cast<std::size_t>(r.ty / per) * blocks_x_;
        for (int b = r.tx0 / per; b <= (r.tx1 - 1) / per; ++b)
          count += value && row[b] == 0, row[b] = value;
      }
    };
    marks(1), marks(0);
    return static_cast<double>(count) / block_mark_.size();
  }
  // A bit per neighbour of cell (x, y) that lies inside the grid.
  unsigned inside_bits(int x, int y) const {
    unsigned bits = 0;
    for (int k = 0; k < 8; ++k) {
      const int nx = x + kNeighbours8[k].dx, ny = y + kNeighbours8[k].dy;
      bits |= static_cast<unsigned>(nx >= 0 && ny >= 0 && nx < w_ && ny < hgt_) << k;
    }
    return bits;
  }
  // For each row of cells of a run: row(i0, i1) on the cells with all 8
  // neighbours inside, edge(i, inside_bits) on the others.
  template <class Row, class Edge>
  void for_run_cells(const TileRun& r, const Row& row, const Edge& edge) const {
    const int x0 = r.tx0 * kTile, x1 = std::min(r.tx1 * kTile, w_);
    const int y0 = r.ty * kTile, y1 = std::min(y0 + kTile, hgt_);
    for (int y = y0; y < y1; ++y) {
      const std::size_t start = static_cast<std::size_t>(y) * w_;
      int a = std::max(x0, 1), b = std::min(x1, w_ - 1);  // the inner cells [a, b)
      if (y == 0 || y == hgt_ - 1 || a >= b) a = b = x1;
      for (int x = x0; x < a; ++x) edge(start + x, inside_bits(x, y));
      if (a < b) row(start + a, start + b);
      for (int x = b; x < x1; ++x) edge(start + x, inside_bits(x, y));
    }
  }
  // Whether a cell of tile (tx, ty) has its flag set.
  bool any_in_tile(const std::vector<std::uint8_t>& flags, int tx, int ty) const {
    const int x0 = tx * kTile, x1 = std::min(x0 + kTile, w_);
    std::uint32_t any = 0;
    for (int y = ty * kTile; y < std::min(ty * kTile + kTile, hgt_); ++y) {
      const std::uint8_t* row = flags.data() + static_cast<std::size_t>(y) * w_ + x0;
      if (x1 - x0 == kTile) {  // a row of the tile as one word
        std::uint32_t word;
        std::memcpy(&word, row, sizeof word);
        any |= word;
      } else {
        for (int x = 0; x < x1 - x0; ++x) any |= row[x];
      }
    }
    return any != 0;
  }
  // Sets a tile's cells' values to v.
  template <class V>
  void fill_tile(std::vector<V>& values, int t, V v) {
    const int x0 = t % tiles_x_ * kTile, y0 = t / tiles_x_ * kTile;
    const int n = std::min(x0 + kTile, w_) - x0;
    for (int y = y0; y < std::min(y0 + kTile, hgt_); ++y)
      std::fill_n(values.begin() + static_cast<std::ptrdiff_t>(y) * w_ + x0, n, v);
  }
  // Tile t's cells stop: not active, giving nothing.
  void stop_tile(int t) {
    fill_tile(active_, t, std::uint8_t{0}), fill_tile(give_, t, kNotGiving);
    tile_active_[static_cast<std::size_t>(t)] = 0;
  }

  // One Jacobi pass: every flow from the state before it. give_, take_ and
  // delta_ need no clearing: every pass writes them for every cell it reads
  // them at (active cells, and the tiles near them).
  void pass() {
    const PassCells& c = c_;
    for_runs(active_runs_, active_tiles_.size(), [&](const TileRun& r) {
      for_run_cells(
          r, [&](std::size_t i0, std::size_t i1) { rows_(Phase::Give, c, i0, i1); },
          [&](std::size_t i, unsigned in) { c.give[i] = c.give_factor<double, false>(i, in); });
    });
    near_ = with_neighbours(active_tiles_);
    const std::vector<TileRun> near = runs_of(near_, tiles_x_);
    for_runs(near, near_.size(), [&](const TileRun& r) {
      for_run_cells(
          r, [&](std::size_t i0, std::size_t i1) { rows_(Phase::Take, c, i0, i1); },
          [&](std::size_t i, unsigned in) { c.touched[i] = c.take_share<double, false>(i, in); });
    });
    for_runs(near, near_.size(), [&](const TileRun& r) {
      for_run_cells(
          r, [&](std::size_t i0, std::size_t i1) { rows_(Phase::Change, c, i0, i1); },
          [&](std::size_t i, unsigned in) { c.touched[i] |= c.change<double, false>(i, in); });
      for (int tx = r.tx0; tx < r.tx1; ++tx)
        tile_touched_[static_cast<std::size_t>(r.ty) * tiles_x_ + tx] =
            any_in_tile(touched_, tx, r.ty);
    });
    // Only cells that gave or took change (delta != 0 needs a flow).
    touched_tiles_.clear();
    for (int t : near_)
      if (tile_touched_[static_cast<std::size_t>(t)]) touched_tiles_.push_back(t);
    for_runs(runs_of(touched_tiles_, tiles_x_), touched_tiles_.size(), [&](const TileRun& r) {
      for_run_cells(
          r, [&](std::size_t i0, std::size_t i1) { rows_(Phase::Apply, c, i0, i1); },
          [&](std::size_t i, unsigned) { c.apply<double>(i); });
    });
  }

  // The tiles of `tiles` (ascending) and their 8 neighbours, ascending: where
  // they are many, marked a row of tiles at a time and read off the marks
  // (8 at a time where none is set); where they are few, marked one by one
  // and sorted.
  std::vector<int> with_neighbours(const std::vector<int>& tiles) {
    std::vector<int> out;
    if (tiles.empty()) return out;
    const int lo = std::max(tiles.front() / tiles_x_ - 1, 0);
    const int hi = std::min(tiles.back() / tiles_x_ + 1, tiles_y_ - 1);
    const std::size_t first = static_cast<std::size_t>(lo) * tiles_x_;
    const std::size_t last = static_cast<std::size_t>(hi + 1) * tiles_x_;
    if (tiles.size() * 64 < last - first) return with_neighbours_sorted(tiles);
    for (const TileRun& r : runs_of(tiles, tiles_x_)) {
      const int x0 = std::max(r.tx0 - 1, 0), x1 = std::min(r.tx1 + 1, tiles_x_);
      for (int j = std::max(r.ty - 1, 0); j <= std::min(r.ty + 1, tiles_y_ - 1); ++j)
        std::fill_n(tile_mark_.begin() + static_cast<std::ptrdiff_t>(j) * tiles_x_ + x0, x1 - x0,
                    std::uint8_t{1});
    }
    std::size_t t = first;
    for (; t + 8 <= last; t += 8) {
      std::uint64_t word;
      std::memcpy(&word, tile_mark_.data() + t, sizeof word);
      if (word == 0) continue;
      for (std::size_t u = t; u < t + 8; ++u)
        if (tile_mark_[u]) out.push_back(static_cast<int>(u)), tile_mark_[u] = 0;
    }
    for (; t < last; ++t)
      if (tile_mark_[t]) out.push_back(static_cast<int>(t)), tile_mark_[t] = 0;
    return out;
  }
  std::vector<int> with_neighbours_sorted(const std::vector<int>& tiles) {
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
  void activate(int x, int y) {
    active_[static_cast<std::size_t>(y) * w_ + x] = 1;
    tile_active_[static_cast<std::size_t>(y / kTile) * tiles_x_ + x / kTile] = 1;
  }
  void set_active_tiles(std::vector<int> tiles) {
    active_tiles_ = std::move(tiles);
    active_runs_ = runs_of(active_tiles_, tiles_x_);
  }
  std::vector<int> tiles_where_active() const {
    std::vector<int> out;
    for (std::size_t t = 0; t < tile_active_.size(); ++t)
      if (tile_active_[t]) out.push_back(static_cast<int>(t));
    return out;
  }
  // The tiles with active cells after a pass; clears the pass's marks.
  std::vector<int> next_active(const std::vector<int>& was_active) {
    const std::vector<int>& touched = touched_tiles_;
    const std::vector<int> candidates = with_neighbours(touched);
    for (int t : candidates) tile_mark_[static_cast<std::size_t>(t)] = 1;
    for (int t : was_active)
      if (!tile_mark_[static_cast<std::size_t>(t)]) stop_tile(t);
    for (int t : candidates) tile_mark_[static_cast<std::size_t>(t)] = 0;
    const PassCells& c = c_;
    for_runs(runs_of(candidates, tiles_x_), candidates.size(), [&](const TileRun& r) {
      for_run_cells(
          r, [&](std::size_t i0, std::size_t i1) { rows_(Phase::NextActive, c, i0, i1); },
          [&](std::size_t i, unsigned in) { c.active[i] = c.next_active<false>(i, in); });
      for (int tx = r.tx0; tx < r.tx1; ++tx) {
        const int t = r.ty * tiles_x_ + tx;
        tile_active_[static_cast<std::size_t>(t)] = any_in_tile(active_, tx, r.ty);
        // A tile that stops gives nothing; in one that goes on, phase 1 marks
        // the cells that stopped.
        if (!tile_active_[static_cast<std::size_t>(t)]) fill_tile(give_, t, kNotGiving);
      }
    });
    terrain::for_each_item(touched, kParallelTiles, [&](int t) {
      fill_tile(touched_, t, std::uint8_t{0});
      tile_touched_[static_cast<std::size_t>(t)] = 0;
    });
    std::vector<int> next;
    for (int t : candidates)
      if (tile_active_[static_cast<std::size_t>(t)]) next.push_back(t);
    return next;
  }

  int w_, hgt_, tiles_x_ = 0, tiles_y_ = 0;
  PassCells c_{};
  RowKernel rows_ = row_kernel();
  std::vector<double> surface_, give_, take_, delta_;
  std::vector<std::uint8_t> active_, touched_;
  std::vector<std::uint8_t> tile_active_, tile_touched_, tile_mark_;
  int blocks_x_ = 0;
  std::vector<std::uint8_t> block_mark_;  // active_share's scratch
  std::vector<int> active_tiles_;
  std::vector<TileRun> active_runs_;  // the same as runs
  int passes_ = 0;
  std::vector<int> near_;           // this pass: active tiles and their neighbours
  std::vector<int> touched_tiles_;  // this pass: tiles where a cell gave or took
};

// Passes, and the shortcut each time they reach their slow tail, until they
// converge (the shortcut only moves snow; convergence is the passes' verdict).
template <class OnPass>
StabiliseReport settle(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                       const SettleGeometry& geo, int max_passes, bool shortcut,
                       std::uint64_t held_bytes_per_cell, const OnPass& on_pass) {
  SnowPasses passes(ground, snow, geo.dx, geo.dy, geo.tan_repose, geo.tolerance);
  int last = 0;
  auto pause = [&](int p, double share) {
    on_pass(p, share);
    return shortcut && p - last >= kTailPasses && share < kTailShare;
  };
  bool converged = false;
  bool counted = false;
  while (!(converged = passes.run(max_passes, pause)) && passes.passes() < max_passes) {
    // The shortcut's workspace, counted when it first runs (on ground that
    // never slides it never does: counted up front, the estimate was 1.37
    // times the peak): envelope (then load) and resting cell, 8 B each, the
    // cut marks, and the loose snow, changed cells and queue entries of the
    // cells it cuts (40 B each; a fifth of them counted, measured 1.05 of
    // the peak on ground steeper than the repose; all of them would be 57 B).
    if (!counted) {
      require_memory(snow.size() * (held_bytes_per_cell + SnowPasses::bytes_per_cell() + 25),
                     "snow stabilisation's workspace and its shortcut",
                     "use a smaller or coarser ground raster");
      counted = true;
    }
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
  StabiliseReport report = settle(ground, snow, geo, options.max_iterations, options.shortcut,
                                  options.held_bytes_per_cell, on_pass);
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
  if (options.direct) {
    // The caller's grids and, with layers, the snow given (8 bytes a cell),
    // held while settle_at_rest counts its own workspace from what it will
    // hold (nothing where no snow can move; snow/stabilise_direct.cpp).
    const std::uint64_t held =
        snow.size() * (options.held_bytes_per_cell + (options.direct_layers > 1 ? 8 : 0));
    require_memory(held, "snow stabilisation's workspace (direct)",
                   "use a smaller or coarser ground raster");
    const HeldMemory held_memory(held, "the ground's grids");
    progress(0.0, "stabilising snow");
    settle_at_rest(ground, snow, dx, dy, terrain::tan_degrees(options.repose_deg),
                   options.direct_layers);
    StabiliseReport report;
    report.converged = max_repose_excess(ground, snow, dx, dy, options.repose_deg,
                                         options.tolerance) <= options.tolerance;
    report.level_passes = {0};
    progress(1.0, "stabilising snow");
    return report;
  }
  // The passes' workspace beside the caller's grids; the shortcut's is
  // counted when it first runs (settle). The coarse levels' grids (ground,
  // snow, its copy and change: 28 bytes a coarse cell, 7 a fine one; the
  // levels below a quarter of that) are freed before the finer level's
  // workspace is made; counted on top as a margin.
  const std::uint64_t coarse_bytes = options.coarse_levels > 0 ? 10 : 0;
  require_memory(
      snow.size() * (options.held_bytes_per_cell + SnowPasses::bytes_per_cell() + coarse_bytes),
      "snow stabilisation's workspace", "use a smaller or coarser ground raster");
  const SettleGeometry geo{dx, dy, terrain::tan_degrees(options.repose_deg), options.tolerance};
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
  const terrain::SlopeRule rule{terrain::tan_degrees(repose_deg), 0.5,
                                terrain::SlopeShare::HalfSteepest};
  terrain::SlopeCells cells{{&rule, 1}};
  cells.base = &ground;
  cells.min_value = 0.0;
  return terrain::max_slope_excess(snow, cells, {dx, dy}, {}, min_snow);
}

}  // namespace drift::snow
