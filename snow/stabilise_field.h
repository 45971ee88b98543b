// Snow on ground as flat arrays, with the repose drop k d to each 8-neighbour:
// the view of a grid that the one-step solver (stabilise_direct.cpp) and the
// settling of unsupported snow (stabilise_settle.cpp) both walk (paper 003,
// 2.1(3): a pair is at rest when the higher surface stands at most k d above
// the lower, k = tan(repose), d the distance between the cells' centres).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdlib>

#include "terrain/grid.h"
#include "terrain/neighbours.h"

namespace drift::snow {

class StabiliseField {
 public:
  // Cells dx by dy metres, k = tan(repose).
  StabiliseField(const terrain::Grid<float>& ground, terrain::Grid<double>& snow, double dx,
                 double dy, double k)
      : g_(ground.values().data()),
        h_(snow.values().data()),
        w_(snow.width()),
        ht_(snow.height()),
        dx_(dx),
        dy_(dy),
        diag_(std::hypot(dx, dy)),
        k_(k) {
    for (int n = 0; n < 8; ++n) {
      drop_[n] = k * std::hypot(terrain::kNeighbours8[n].dx * dx, terrain::kNeighbours8[n].dy * dy);
      offset_[n] = static_cast<std::ptrdiff_t>(terrain::kNeighbours8[n].dy) * w_ +
                   terrain::kNeighbours8[n].dx;
    }
  }
  std::size_t cells() const { return static_cast<std::size_t>(w_) * ht_; }
  double ground(std::size_t i) const { return g_[i]; }
  double& snow(std::size_t i) const { return h_[i]; }
  double surface(std::size_t i) const { return static_cast<double>(g_[i]) + h_[i]; }
  // Whether cell i's neighbour in direction n (terrain::kNeighbours8) lies
  // inside the grid, and which cell it is.
  bool inside(std::size_t i, int n) const {
    const int x = static_cast<int>(i % w_) + terrain::kNeighbours8[n].dx,
              y = static_cast<int>(i / w_) + terrain::kNeighbours8[n].dy;
    return x >= 0 && y >= 0 && x < w_ && y < ht_;
  }
  std::size_t neighbour(std::size_t i, int n) const { return i + offset_[n]; }
  // Calls fn(neighbour, direction) for the 8-neighbours inside the grid, in a fixed order.
  template <class Fn>
  void neighbours(std::size_t i, const Fn& fn) const {
    for (int n = 0; n < 8; ++n)
      if (inside(i, n)) fn(neighbour(i, n), n);
  }
  // The repose drop to the neighbour in direction n: k d.
  double drop(int n) const { return drop_[n]; }
  // The cone's drop from its apex p to i: k x the 8-neighbour path distance
  // (diagonal steps, then straight ones, the octagonal distance), so that it
  // falls by exactly drop(n) or less along every step.
  double cone_drop(std::size_t p, std::size_t i) const {
    const long ax = std::labs(static_cast<long>(i % w_) - static_cast<long>(p % w_));
    const long ay = std::labs(static_cast<long>(i / w_) - static_cast<long>(p / w_));
    const long m = std::min(ax, ay);
    return k_ * (m * diag_ + (ax - m) * dx_ + (ay - m) * dy_);
  }

 private:
  const float* g_;
  double* h_;
  int w_, ht_;
  double dx_, dy_, diag_, k_;
  std::array<double, 8> drop_{};
  std::array<std::ptrdiff_t, 8> offset_{};
};

}  // namespace drift::snow
