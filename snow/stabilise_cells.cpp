#include "snow/stabilise_cells.h"

#include <cstring>

#include "terrain/simd.h"

namespace drift::snow::kernel {

namespace {

// The row kernels: cells [i0, i1) of one row, all with 8 neighbours inside,
// a vector of lanes at a time and the rest one by one.
template <class Lanes>
[[gnu::always_inline]] inline void run_row(Phase phase, const PassCells& cells, std::size_t i0,
                                           std::size_t i1) {
  // A local copy: the stores (memcpy) cannot reach it, so its pointers stay in
  // registers instead of being reloaded after every store.
  const PassCells c = cells;
  std::size_t i = i0;
  switch (phase) {
    case Phase::Give:
      for (; i + kWidth<Lanes> <= i1; i += kWidth<Lanes>)
        store(c.give + i, c.give_factor<Lanes, true>(i, 0xffu));
      for (; i < i1; ++i) c.give[i] = c.give_factor<double, true>(i, 0xffu);
      return;
    case Phase::Take:
      for (; i + kWidth<Lanes> <= i1; i += kWidth<Lanes>) {
        const auto took = c.take_share<Lanes, true>(i, 0xffu);
        for (int l = 0; l < kWidth<Lanes>; ++l) c.touched[i + l] = took[l] != 0;
      }
      for (; i < i1; ++i) c.touched[i] = c.take_share<double, true>(i, 0xffu);
      return;
    case Phase::Change:
      for (; i + kWidth<Lanes> <= i1; i += kWidth<Lanes>) {
        const auto moved = c.change<Lanes, true>(i, 0xffu);
        for (int l = 0; l < kWidth<Lanes>; ++l) c.touched[i + l] |= moved[l] != 0;
      }
      for (; i < i1; ++i) c.touched[i] |= c.change<double, true>(i, 0xffu);
      return;
    case Phase::Apply:
      for (; i + kWidth<Lanes> <= i1; i += kWidth<Lanes>) c.apply<Lanes>(i);
      for (; i < i1; ++i) c.apply<double>(i);
      return;
    case Phase::NextActive:
      for (; i + 16 <= i1; i += 16) {  // 16 cells' flags in one SSE2 register
        using Flags = std::uint8_t __attribute__((vector_size(16)));
        Flags any, next;
        std::memcpy(&any, c.touched + i, sizeof any);
        for (int k = 0; k < 8; ++k) {
          std::memcpy(&next, c.touched + i + c.offset[k], sizeof next);
          any |= next;
        }
        const Flags active = (any != 0) & 1;
        std::memcpy(c.active + i, &active, sizeof active);
      }
      for (; i < i1; ++i) c.active[i] = c.next_active<true>(i, 0xffu);
      return;
  }
}
// The row kernels built for any x86-64 (SSE2) and for AVX2 (no FMA: each
// product is rounded on its own, as in the scalar path), picked by
// terrain/simd.h as every hot loop's twins are (DRIFT_SIMD=sse2 or a
// simd::Limit forces the first; the tests compare the two builds' bits).
void rows_baseline(Phase phase, const PassCells& c, std::size_t i0, std::size_t i1) {
  run_row<Lanes2>(phase, c, i0, i1);
}
#ifdef DRIFT_SIMD_X86
__attribute__((target("avx2"))) void rows_avx2(Phase phase, const PassCells& c, std::size_t i0,
                                               std::size_t i1) {
  run_row<Lanes4>(phase, c, i0, i1);
}
#endif
}  // namespace

RowKernel row_kernel() {
#ifdef DRIFT_SIMD_X86
  if (simd::active() == simd::Isa::Avx2) return rows_avx2;
#endif
  return rows_baseline;
}

}  // namespace drift::snow::kernel
