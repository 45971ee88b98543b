// Several cells of a row at once, for the snow stabilisation's row kernels
// (snow/stabilise_cells.h): GCC vector extensions of 2 lanes (one SSE2
// register, any x86-64) or 4 (one AVX2 register), and the few operations the
// kernels need, each written so that a double (one cell) works too. Each lane
// does the scalar operations in their order, so lanes give the same bits as
// one cell at a time. Everything here is inlined into the kernels, so no
// vector crosses a call (hence no ABI question: -Wpsabi is quiet).
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>

#pragma GCC diagnostic ignored "-Wpsabi"

namespace drift::snow::kernel {

// kN lanes of each element type. (A typedef: GCC ignores a vector_size that
// depends on a template parameter in an alias declaration, not in a typedef.)
template <int kN>
struct LaneTypes {
  typedef double Values __attribute__((vector_size(kN * sizeof(double))));
  typedef std::int64_t Mask __attribute__((vector_size(kN * sizeof(std::int64_t))));
  typedef std::uint8_t Bytes __attribute__((vector_size(kN * sizeof(std::uint8_t))));
  typedef float Floats __attribute__((vector_size(kN * sizeof(float))));
};
using Lanes2 = LaneTypes<2>::Values;
using Lanes4 = LaneTypes<4>::Values;
static_assert(sizeof(Lanes2) == 16 && sizeof(Lanes4) == 32);
static_assert(sizeof(LaneTypes<4>::Mask) == 32 && sizeof(LaneTypes<4>::Bytes) == 4 &&
              sizeof(LaneTypes<4>::Floats) == 16);
// A comparison's result: bool for one cell, a lane mask for lanes.
template <class T>
using MaskOf = decltype(T{} > 0.0);
// The number of cells in a T (double or lanes).
template <class T>
constexpr int kWidth = sizeof(T) / sizeof(double);

template <class T>
[[gnu::always_inline]] inline T load(const double* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <class T>
[[gnu::always_inline]] inline void store(double* p, T v) {
  std::memcpy(p, &v, sizeof v);
}
template <class T>
[[gnu::always_inline]] inline T splat(double v) {
  if constexpr (std::is_same_v<T, double>)
    return v;
  else
    return T{} + v;
}
// Whether the flag of each cell is set: bool for one cell, a lane mask for lanes.
template <class T>
[[gnu::always_inline]] inline auto is_set(const std::uint8_t* p) {
  if constexpr (std::is_same_v<T, double>) {
    return *p != 0;
  } else {
    using L = LaneTypes<kWidth<T>>;
    typename L::Bytes b;
    std::memcpy(&b, p, sizeof b);
    return __builtin_convertvector(b, typename L::Mask) != 0;
  }
}
// Whether no lane (or the one cell) is set.
template <class M>
[[gnu::always_inline]] inline bool none(M set) {
  if constexpr (std::is_same_v<M, bool>) {
    return !set;
  } else {
    std::int64_t any = 0;
    for (std::size_t l = 0; l < sizeof(M) / sizeof(std::int64_t); ++l) any |= set[l];
    return any == 0;
  }
}
// Ground heights as doubles.
template <class T>
[[gnu::always_inline]] inline T to_double(const float* p) {
  if constexpr (std::is_same_v<T, double>) {
    return static_cast<double>(*p);
  } else {
    typename LaneTypes<kWidth<T>>::Floats f;
    std::memcpy(&f, p, sizeof f);
    return __builtin_convertvector(f, T);
  }
}
// std::max and std::min written so that lanes work too (the same choices).
template <class T>
[[gnu::always_inline]] inline T larger(T a, T b) {
  return a < b ? b : a;
}
template <class T>
[[gnu::always_inline]] inline T smaller(T a, T b) {
  return b < a ? b : a;
}

}  // namespace drift::snow::kernel
