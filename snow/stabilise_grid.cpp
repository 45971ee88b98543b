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

constexpr int kTile = 16;

struct Offset {
  int dx, dy;
};
// East, west, north, south (rows run south), then the diagonals.
constexpr std::array<Offset, 8> kNeighbours{
    {{1, 0}, {-1, 0}, {0, -1}, {0, 1}, {1, -1}, {-1, -1}, {1, 1}, {-1, 1}}};

// tan(repose) x the distance to each neighbour; opposite offsets share a value
// bit for bit, so a giver and its receiver work out the same excess.
std::array<double, 8> repose_reach(double tan_repose, double dx, double dy) {
  const double diagonal = tan_repose * std::hypot(dx, dy);
  return {tan_repose * dx, tan_repose * dx, tan_repose * dy, tan_repose * dy,
          diagonal,        diagonal,        diagonal,        diagonal};
}

// A colour: the cells with x % 2 == cx and y % 2 == cy. No two are neighbours.
struct Colour {
  int cx, cy;
  bool has(int x, int y) const { return (x & 1) == cx && (y & 1) == cy; }
};
constexpr std::array<Colour, 4> kColours{{{0, 0}, {1, 1}, {1, 0}, {0, 1}}};

// The square tiles of the grid and which of them work in a pass.
struct Tiles {
  int w, h, across, down;
  std::vector<unsigned char> active;  // may give snow this pass
  std::vector<unsigned char> nearby;  // active or next to an active tile: may receive
  std::vector<double> moved;          // largest amount given in the tile this pass
  std::vector<unsigned char> shared;  // may hold shares from a turn (cleared when asleep)

  Tiles(int width, int height)
      : w(width),
        h(height),
        across((width + kTile - 1) / kTile),
        down((height + kTile - 1) / kTile) {
    active.assign(count(), 1);
    nearby.assign(count(), 1);
    moved.assign(count(), 0.0);
    shared.assign(count(), 0);
  }
  std::size_t count() const { return static_cast<std::size_t>(across) * down; }
  int x0(std::size_t t) const { return static_cast<int>(t % across) * kTile; }
  int y0(std::size_t t) const { return static_cast<int>(t / across) * kTile; }
  int x1(std::size_t t) const { return std::min(x0(t) + kTile, w); }
  int y1(std::size_t t) const { return std::min(y0(t) + kTile, h); }

  // Whether `flag` is set for any tile of the 3 x 3 block around tile (tx, ty).
  template <class Flag>
  bool around(int tx, int ty, Flag flag) const {
    for (int j = std::max(ty - 1, 0); j <= std::min(ty + 1, down - 1); ++j)
      for (int i = std::max(tx - 1, 0); i <= std::min(tx + 1, across - 1); ++i)
        if (flag(static_cast<std::size_t>(j) * across + i)) return true;
    return false;
  }

  // Wakes every tile for a checking pass (amounts below the tolerance that a
  // sleeping tile received may have added up).
  void wake_all() {
    std::fill(active.begin(), active.end(), 1);
    std::fill(nearby.begin(), nearby.end(), 1);
  }
  bool all_awake() const {
    return std::all_of(active.begin(), active.end(), [](auto a) { return a != 0; });
  }

  // After a pass: a tile works next pass if it or a neighbour moved more than
  // `tolerance`. Returns how many tiles are awake.
  std::size_t wake(double tolerance) {
    std::vector<unsigned char> next(count(), 0);
    std::size_t awake = 0;
    for (int ty = 0; ty < down; ++ty)
      for (int tx = 0; tx < across; ++tx) {
        const bool moving = around(tx, ty, [&](std::size_t t) { return moved[t] > tolerance; });
        next[static_cast<std::size_t>(ty) * across + tx] = moving;
        awake += moving;
      }
    active.swap(next);
    for (int ty = 0; ty < down; ++ty)
      for (int tx = 0; tx < across; ++tx)
        nearby[static_cast<std::size_t>(ty) * across + tx] =
            around(tx, ty, [&](std::size_t t) { return active[t] != 0; });
    std::fill(moved.begin(), moved.end(), 0.0);
    return awake;
  }
};

// One stabilisation: the fields and the three steps of a colour's turn.
class Stabiliser {
 public:
  Stabiliser(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
             std::array<double, 8> reach)
      : ground_(ground),
        snow_(snow),
        w_(ground.width()),
        h_(ground.height()),
        reach_(reach),
        share_(w_, h_, 0.0),
        given_(w_, h_, 0.0),
        tiles_(w_, h_) {}

  Tiles& tiles() { return tiles_; }

  // One colour's turn: shares from the state before it, then receive, then give.
  void turn(Colour c) {
    const std::size_t n = tiles_.count();
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t t) {
      if (tiles_.active[t]) {
        work_out_shares(t, c);
        tiles_.shared[t] = 1;
      } else if (tiles_.shared[t]) {  // asleep: no shares left from its last turns
        clear_shares(t);
        tiles_.shared[t] = 0;
      }
    });
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t t) {
      if (tiles_.nearby[t]) receive(t, c);
    });
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t t) {
      if (tiles_.active[t]) give(t, c);
    });
  }

 private:
  double surface(int x, int y) const { return ground_(x, y) + snow_(x, y); }
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < w_ && y < h_; }

  // Excess of the slope from (x, y) down to neighbour k over the repose angle
  // (0 if it is not steeper, or off the grid: closed edges).
  double excess(int x, int y, double high, int k) const {
    const int nx = x + kNeighbours[k].dx, ny = y + kNeighbours[k].dy;
    if (!inside(nx, ny)) return 0.0;
    return std::max(high - surface(nx, ny) - reach_[k], 0.0);
  }

  // The paper's three cases for one giver: nothing lower, one, several (shared in
  // proportion to the excess). share x excess is what each neighbour gets.
  void shares_of(int x, int y) {
    share_(x, y) = given_(x, y) = 0.0;
    const double s = snow_(x, y);
    if (s <= 0.0) return;
    const double high = surface(x, y);
    double sum = 0.0, steepest = 0.0;
    for (int k = 0; k < 8; ++k) {
      const double e = excess(x, y, high, k);
      sum += e;
      steepest = std::max(steepest, e);
    }
    if (sum == 0.0) return;  // case (1)
    const double share = std::min(s, 0.5 * steepest) / sum;
    double given = 0.0;  // the receivers' amounts, as they will work them out
    for (int k = 0; k < 8; ++k) given += share * excess(x, y, high, k);
    share_(x, y) = share;
    given_(x, y) = given;
  }

  void work_out_shares(std::size_t t, Colour c) {
    for (int y = tiles_.y0(t); y < tiles_.y1(t); ++y) {
      if ((y & 1) != c.cy) continue;
      for (int x = tiles_.x0(t) + ((tiles_.x0(t) & 1) != c.cx); x < tiles_.x1(t); x += 2)
        shares_of(x, y);
    }
  }

  void clear_shares(std::size_t t) {
    for (int y = tiles_.y0(t); y < tiles_.y1(t); ++y)
      std::fill(&share_(tiles_.x0(t), y), &share_(tiles_.x0(t), y) + (tiles_.x1(t) - tiles_.x0(t)),
                0.0);
  }

  // What (x, y), not of colour c, gets from its neighbours of colour c.
  double inflow(int x, int y, Colour c) const {
    double in = 0.0;
    const double low = surface(x, y);
    for (int k = 0; k < 8; ++k) {
      const int gx = x + kNeighbours[k].dx, gy = y + kNeighbours[k].dy;
      if (!inside(gx, gy) || !c.has(gx, gy) || share_(gx, gy) <= 0.0) continue;
      // The giver's excess towards us: the same operands as in shares_of.
      const double e = std::max(surface(gx, gy) - low - reach_[k], 0.0);
      in += share_(gx, gy) * e;
    }
    return in;
  }

  void receive(std::size_t t, Colour c) {
    for (int y = tiles_.y0(t); y < tiles_.y1(t); ++y)
      for (int x = tiles_.x0(t); x < tiles_.x1(t); ++x)
        if (!c.has(x, y)) snow_(x, y) += inflow(x, y, c);
  }

  void give(std::size_t t, Colour c) {
    double largest = tiles_.moved[t];
    for (int y = tiles_.y0(t); y < tiles_.y1(t); ++y) {
      if ((y & 1) != c.cy) continue;
      for (int x = tiles_.x0(t) + ((tiles_.x0(t) & 1) != c.cx); x < tiles_.x1(t); x += 2) {
        snow_(x, y) -= given_(x, y);
        largest = std::max(largest, given_(x, y));
      }
    }
    tiles_.moved[t] = largest;
  }

  const terrain::Grid<float>& ground_;
  terrain::Grid<double>& snow_;
  int w_, h_;
  std::array<double, 8> reach_;
  terrain::Grid<double> share_, given_;  // per giver of the current colour
  Tiles tiles_;
};

}  // namespace

StabiliseReport stabilise_grid(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                               double dx, double dy, const StabiliseOptions& options,
                               const ProgressFn& progress) {
  if (!(options.repose_deg > 0.0 && options.repose_deg < 90.0))
    throw Error("the angle of repose of snow must lie in (0, 90) degrees");
  const double tan_repose = std::tan(options.repose_deg * std::numbers::pi / 180.0);
  Stabiliser stabiliser(ground, snow, repose_reach(tan_repose, dx, dy));
  Tiles& tiles = stabiliser.tiles();
  StabiliseReport report;
  for (int pass = 0; pass < options.max_iterations; ++pass) {
    const bool checking = tiles.all_awake();
    for (const Colour& c : kColours) stabiliser.turn(c);
    report.iterations = pass + 1;
    std::size_t awake = tiles.wake(options.tolerance);
    if (awake == 0 && checking) {  // a pass over every tile moved nothing: stable
      report.converged = true;
      break;
    }
    if (awake == 0) tiles.wake_all(), awake = tiles.count();
    if (!progress(1.0 - static_cast<double>(awake) / tiles.count(), "stabilising snow"))
      throw Cancelled();
  }
  progress(1.0, "stabilising snow");
  return report;
}

double max_repose_excess(const terrain::Grid<float>& ground, const terrain::Grid<double>& snow,
                         double dx, double dy, double repose_deg, double min_snow) {
  const auto reach = repose_reach(std::tan(repose_deg * std::numbers::pi / 180.0), dx, dy);
  const int w = ground.width(), h = ground.height();
  auto rows = [&](const tbb::blocked_range<int>& r, double m) {
    for (int y = r.begin(); y < r.end(); ++y)
      for (int x = 0; x < w; ++x) {
        if (snow(x, y) <= min_snow) continue;
        const double high = ground(x, y) + snow(x, y);
        for (int k = 0; k < 8; ++k) {
          const int nx = x + kNeighbours[k].dx, ny = y + kNeighbours[k].dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          m = std::max(m, high - (ground(nx, ny) + snow(nx, ny)) - reach[k]);
        }
      }
    return m;
  };
  return tbb::parallel_reduce(tbb::blocked_range<int>(0, h), 0.0, rows,
                              [](double a, double b) { return std::max(a, b); });
}

}  // namespace drift::snow
