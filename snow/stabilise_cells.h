// The per-cell rules of snow stabilisation's passes (snow/stabilise_grid.h)
// and the row kernels that run them over the cells with all 8 neighbours
// inside, several cells at a time (snow/stabilise_lanes.h). The grid's edge
// cells go through the same rules one at a time with their missing neighbours
// skipped, so every cell gets the same bits.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "snow/stabilise_lanes.h"

namespace drift::snow::kernel {

// The per-cell rules of a pass: terrain/slope_relax's HalfSteepest passes for
// snow on ground (one rule, floor 0, no ceiling), the same operations in the
// same order, so the same bits. T: double for one cell, lanes for several
// cells of a row whose 8 neighbours are all inside. kAllInside: no edge tests;
// otherwise `inside` has a bit per neighbour and the missing ones are skipped.
// Every sum adds 0.0 for a neighbour that does not count and every choice is
// made after both sides are computed, which keeps the bits of skipping (a sum
// of positive terms plus 0.0 is itself) without branches.
constexpr double kNotGiving = -1.0;  // below every factor (they are >= 0)
struct PassCells {
  const float* ground;
  double* snow;
  double* surface;  // ground + snow
  // Phase 1: a giver's factor per unit of excess, kNotGiving at every cell
  // that is not active (the later phases read a neighbour's activity from it,
  // not from its flag: fewer loads).
  double* give;
  double* take;   // phase 2: the share of its offers a taker takes
  double* delta;  // phase 2: what a taker takes; phase 3: taken - given
  std::uint8_t* active;
  std::uint8_t* touched;
  std::array<std::ptrdiff_t, 8> offset;
  std::array<double, 8> drop;  // tan(repose) x the distance to neighbour k
  double tol;

  // Phase 1, paper 003 2.1(3): a giver gives min(held, e_max / 2), shared
  // among its steeper neighbours in proportion to their excess.
  template <class T, bool kAllInside>
  [[gnu::always_inline]] T give_factor(std::size_t i, unsigned inside) const {
    T sum{}, largest{};
    const T here = load<T>(surface + i), zero{};
    const T room = larger(load<T>(snow + i) - 0.0, zero);
    const auto active_here = is_set<T>(active + i);
    // Bare cells give nothing whatever their neighbours (the result below).
    if (none(room > tol)) return active_here ? zero : splat<T>(kNotGiving);
    for (int k = 0; k < 8; ++k) {
      if (!kAllInside && !(inside >> k & 1u)) continue;
      const T e = here - load<T>(surface + i + offset[k]) - drop[k];
      const T over = e > tol ? e : zero;
      sum += over;
      largest = larger(largest, over);
    }
    const T factor = smaller(room, 0.5 * largest) / (sum > 0.0 ? sum : splat<T>(1.0));
    const T given = (sum > 0.0) & (room > tol) ? factor : zero;
    return active_here ? given : splat<T>(kNotGiving);
  }
  // Phase 2: the share of its offers a taker takes (half the largest excess it
  // is offered from), the offers being those of active steeper neighbours;
  // and what it takes, since that needs nothing more: each offer times the
  // share, the flow its giver computes in phase 3 from the same operands, summed
  // into delta. Stores take and delta; returns whether the cell took.
  template <class T, bool kAllInside>
  [[gnu::always_inline]] MaskOf<T> take_share(std::size_t i, unsigned inside) const {
    T in{}, largest{}, offers[8] = {};
    const T here = load<T>(surface + i), zero{};
    // No neighbour giving: every offer is 0.0, nothing is taken (the result below).
    T most{};
    for (int k = 0; k < 8; ++k)
      if (kAllInside || inside >> k & 1u) most = larger(most, load<T>(give + i + offset[k]));
    if (none(most > 0.0)) {
      store(take + i, zero), store(delta + i, zero);
      return most > 0.0;
    }
    for (int k = 0; k < 8; ++k) {
      if (!kAllInside && !(inside >> k & 1u)) continue;
      const std::size_t n = i + offset[k];
      const T e = load<T>(surface + n) - here - drop[7 - k];
      const T give_n = load<T>(give + n);
      // Not offered: an excess of 0.0, so an offer of +-0.0, which leaves the
      // sums' bits (x + -0.0 is x, +0.0 + -0.0 is +0.0).
      const T excess = (give_n >= 0.0) & (e > tol) ? e : zero;
      offers[k] = give_n * excess;
      in += offers[k];
      largest = larger(largest, excess);
    }
    const T share = smaller(splat<T>(1.0), 0.5 * largest / (in > 0.0 ? in : splat<T>(1.0)));
    const auto takes = in > 0.0;
    const T taken_share = takes ? share : zero;
    // An offer of +-0.0 (none) flows as +-0.0: the sum's bits. The flows are
    // >= 0, so one of them is > 0 exactly where their sum is.
    T taken{};
    for (int k = 0; k < 8; ++k) {
      if (!kAllInside && !(inside >> k & 1u)) continue;
      taken += offers[k] * taken_share;
    }
    store(take + i, taken_share);
    store(delta + i, takes ? taken : zero);
    return MaskOf<T>(takes & (taken > 0.0));
  }
  // Phase 3: the change of cell i, taken (phase 2) - given, each outflow
  // computed from the same operands as its taker computed it; returns whether
  // the cell gave.
  template <class T, bool kAllInside>
  [[gnu::always_inline]] MaskOf<T> change(std::size_t i, unsigned inside) const {
    T out{};
    const T here = load<T>(surface + i), give_here = load<T>(give + i), zero{};
    const auto gives = give_here > 0.0;
    // Not giving: delta keeps what was taken (x - 0.0 is x), the result below.
    if (none(gives)) return gives;
    for (int k = 0; k < 8; ++k) {
      if (!kAllInside && !(inside >> k & 1u)) continue;
      const std::size_t n = i + offset[k];
      const T down = here - load<T>(surface + n) - drop[k];
      const T flow_out = give_here * down * load<T>(take + n);
      out += down > tol ? flow_out : zero;
    }
    store(delta + i, load<T>(delta + i) - (gives ? out : zero));
    // A giver's flows are >= 0: one is > 0 exactly where their sum is.
    return MaskOf<T>(gives & (out > 0.0));
  }
  // The change applied, only where there is one (h + 0.0 would turn -0.0 into
  // 0.0; and cells that did not move are not written).
  template <class T>
  [[gnu::always_inline]] void apply(std::size_t i) const {
    const T d = load<T>(delta + i), h = load<T>(snow + i);
    if (none(d != 0.0)) return;
    const T moved = h + d, held = d == 0.0 ? h : moved;
    store(snow + i, held);
    store(surface + i, to_double<T>(ground + i) + held);
  }
  // Whether cell i is active next pass: it or a neighbour gave or took.
  template <bool kAllInside>
  [[gnu::always_inline]] std::uint8_t next_active(std::size_t i, unsigned inside) const {
    unsigned any = touched[i];
    for (int k = 0; k < 8; ++k) {
      if (!kAllInside && !(inside >> k & 1u)) continue;
      any |= touched[i + offset[k]];
    }
    return any != 0;
  }
};

// The phases of a pass, in their order.
enum class Phase { Give, Take, Change, Apply, NextActive };
// Runs `phase` on cells [i0, i1) of one row, all with 8 neighbours inside.
using RowKernel = void (*)(Phase, const PassCells&, std::size_t, std::size_t);
// The row kernels built for AVX2 where terrain/simd.h says the CPU runs it
// (the tests compare the two builds' bits); else those built for any x86-64
// (SSE2).
RowKernel row_kernel();

}  // namespace drift::snow::kernel
