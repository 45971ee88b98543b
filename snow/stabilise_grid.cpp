#include "snow/stabilise_grid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "terrain/error.h"

namespace drift::snow {

namespace {

constexpr int kTile = 64;
// Neighbour offsets: east, west, north, south; kOpposite[d] points back.
constexpr std::array<int, 4> kDx{1, -1, 0, 0}, kDy{0, 0, -1, 1}, kOpposite{1, 0, 3, 2};

struct Field {
  const terrain::Grid<float>& ground;
  const terrain::Grid<double>& snow;
  int w, h;
  std::array<double, 4> reach;  // tan(repose) * distance to each neighbour
  double omega = 1.0;           // over-relaxation of the amount given

  double surface(int x, int y) const { return ground(x, y) + snow(x, y); }

  // The flows out of (x, y) to its 4 neighbours: the paper's three cases.
  std::array<double, 4> flows(int x, int y) const {
    std::array<double, 4> f{0, 0, 0, 0};
    const double s = snow(x, y);
    if (s <= 0.0) return f;
    const double hi = surface(x, y);
    double sum = 0.0, steepest = 0.0;
    for (int d = 0; d < 4; ++d) {
      const int nx = x + kDx[d], ny = y + kDy[d];
      if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;  // closed edge
      const double e = hi - surface(nx, ny) - reach[d];
      if (e > 0.0) f[d] = e, sum += e, steepest = std::max(steepest, e);
    }
    if (sum == 0.0) return f;  // case (1)
    const double out = std::min(s, omega * 0.5 * steepest);
    for (double& v : f) v = v * (out / sum);  // case (2): one term; case (3): shared
    return f;
  }
};

// Which tiles work: a tile sleeps once it and its neighbours had nothing to
// give for two passes (both colours), and only tiles next to a working one
// are visited.
struct TileSchedule {
  int w, h, tw, th;
  std::size_t tiles;
  // active: may give snow; processed: active or next to an active tile (may receive).
  std::vector<unsigned char> active, processed;
  std::vector<int> written;  // the pass that last wrote the tile into `next`
  std::vector<double> tile_max, tile_before;

  TileSchedule(int w_, int h_)
      : w(w_),
        h(h_),
        tw((w_ + kTile - 1) / kTile),
        th((h_ + kTile - 1) / kTile),
        tiles(static_cast<std::size_t>(tw) * th),
        active(tiles, 1),
        processed(tiles, 1),
        written(tiles, -2),
        tile_max(tiles, 0.0),
        tile_before(tiles, 0.0) {}

  std::size_t tile_of(int x, int y) const {
    return static_cast<std::size_t>(y / kTile) * tw + x / kTile;
  }
  // Whether any tile in the 3 x 3 tiles around (tx, ty) satisfies `f(index)`.
  template <class F>
  bool around(int tx, int ty, const F& f) const {
    for (int j = std::max(ty - 1, 0); j <= std::min(ty + 1, th - 1); ++j)
      for (int i = std::max(tx - 1, 0); i <= std::min(tx + 1, tw - 1); ++i)
        if (f(static_cast<std::size_t>(j) * tw + i)) return true;
    return false;
  }
  // After a pass: a tile works next pass if it or a neighbour moved more than
  // `tolerance`. Returns how many do.
  std::size_t wake(double tolerance) {
    std::size_t awake = 0;
    for (int ty = 0; ty < th; ++ty)
      for (int tx = 0; tx < tw; ++tx) {
        const bool moving = around(tx, ty, [&](std::size_t k) {
          return std::max(tile_max[k], tile_before[k]) > tolerance;
        });
        active[static_cast<std::size_t>(ty) * tw + tx] = moving;
        awake += moving;
      }
    tile_before = tile_max;  // a tile sleeps only after both colours had nothing to give
    for (int ty = 0; ty < th; ++ty)
      for (int tx = 0; tx < tw; ++tx)
        processed[static_cast<std::size_t>(ty) * tw + tx] =
            around(tx, ty, [&](std::size_t k) { return active[k] != 0; });
    return awake;
  }
};

// One pass over one tile: cells of `colour` give (if the tile is active),
// the others receive from active neighbours; the result goes to `next`.
void pass_tile(const Field& field, TileSchedule& s, std::size_t tile, int it, int colour,
               terrain::Grid<double>& next) {
  const terrain::Grid<double>& snow = field.snow;
  const int w = s.w, h = s.h;
  const int x0 = static_cast<int>(tile % s.tw) * kTile, y0 = static_cast<int>(tile / s.tw) * kTile;
  const int x1 = std::min(x0 + kTile, w), y1 = std::min(y0 + kTile, h);
  if (!s.processed[tile]) {
    s.tile_max[tile] = 0.0;
    if (s.written[tile] == it - 1) {  // the other buffer is stale here: bring it level
      for (int y = y0; y < y1; ++y) std::copy(&snow(x0, y), &snow(x0, y) + (x1 - x0), &next(x0, y));
    }
    return;
  }
  double largest = 0.0;
  const bool gives = s.active[tile];
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const bool my_turn = ((x + y) & 1) == colour;
      const auto out = gives && my_turn ? field.flows(x, y) : std::array<double, 4>{0, 0, 0, 0};
      double v = snow(x, y) - ((out[0] + out[1]) + (out[2] + out[3]));
      largest = std::max(largest, (out[0] + out[1]) + (out[2] + out[3]));
      for (int d = 0; d < 4; ++d) {
        const int nx = x + kDx[d], ny = y + kDy[d];
        if (my_turn || nx < 0 || ny < 0 || nx >= w || ny >= h || !s.active[s.tile_of(nx, ny)])
          continue;
        v += field.flows(nx, ny)[kOpposite[d]];
      }
      next(x, y) = v;
    }
  s.tile_max[tile] = largest;
  s.written[tile] = it;
}

}  // namespace

StabiliseReport stabilise_grid(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                               double dx, double dy, const StabiliseOptions& options,
                               const ProgressFn& progress) {
  if (!(options.repose_deg > 0.0 && options.repose_deg < 90.0))
    throw Error("the angle of repose of snow must lie in (0, 90) degrees");
  if (!(options.relaxation >= 1.0 && options.relaxation <= 1.95))
    throw Error("the stabilisation's over-relaxation must lie in [1, 1.95]");
  const int w = ground.width(), h = ground.height();
  const double t = std::tan(options.repose_deg * std::numbers::pi / 180.0);
  TileSchedule schedule(w, h);
  terrain::Grid<double> next(w, h, 0.0);
  StabiliseReport report;
  for (int it = 0; it < options.max_iterations; ++it) {
    // Red-black: in even passes cells with x + y even give, in odd passes the others,
    // so a cell never gives and receives in the same pass (Gauss-Seidel order,
    // parallel and independent of the thread count).
    const int colour = it & 1;
    Field field{ground, snow, w, h, {t * dx, t * dx, t * dy, t * dy}};
    field.omega = options.relaxation;
    tbb::parallel_for(std::size_t{0}, schedule.tiles, [&](std::size_t tile) {
      pass_tile(field, schedule, tile, it, colour, next);
    });
    std::swap(snow.values(), next.values());
    report.iterations = it + 1;
    const std::size_t awake = schedule.wake(options.tolerance);
    if (awake == 0) {
      report.converged = true;
      break;
    }
    if (!progress(1.0 - static_cast<double>(awake) / schedule.tiles, "stabilising snow"))
      throw Cancelled();
  }
  // Both buffers may disagree only in tiles written last pass; `snow` holds the newest.
  progress(1.0, "stabilising snow");
  return report;
}

double max_repose_excess(const terrain::Grid<float>& ground, const terrain::Grid<double>& snow,
                         double dx, double dy, double repose_deg, double min_snow) {
  const double t = std::tan(repose_deg * std::numbers::pi / 180.0);
  const int w = ground.width(), h = ground.height();
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, h), 0.0,
      [&](const tbb::blocked_range<int>& rows, double m) {
        for (int y = rows.begin(); y < rows.end(); ++y)
          for (int x = 0; x < w; ++x) {
            if (snow(x, y) <= min_snow) continue;
            const double hi = ground(x, y) + snow(x, y);
            for (int d = 0; d < 4; ++d) {
              const int nx = x + kDx[d], ny = y + kDy[d];
              if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
              m = std::max(m, hi - (ground(nx, ny) + snow(nx, ny)) - t * (d < 2 ? dx : dy));
            }
          }
        return m;
      },
      [](double a, double b) { return std::max(a, b); });
}

}  // namespace drift::snow
