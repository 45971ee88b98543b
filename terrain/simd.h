// Which vector instructions hot loops run with, chosen once at run time.
//
// The build targets baseline x86-64 (SSE2: no -march=native, so binaries and
// golden images hold on any CI host). A hot loop may also be compiled for
// AVX2 (DRIFT_SIMD_TWINS below) and dispatched by the CPU it runs on. Both
// compilations must do the same IEEE operations lane by lane: elementwise
// float arithmetic without FMA (AVX2 alone does not enable FMA, and modules
// with twins link drift_simd_twins, which builds them with -ffp-contract=off),
// no reassociated reductions. Then the bits are the same on any machine;
// tests check this by running both.
#pragma once

// Defined where a loop can have an AVX2 twin (x86-64 with GCC or Clang).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define DRIFT_SIMD_X86 1
#endif

namespace drift::simd {

enum class Isa { Sse2, Avx2 };

// The widest instruction set the CPU has, or less while a Limit is alive.
Isa active();

// Caps active() at `isa` for its lifetime (tests compare the twins; not
// thread-safe: create it before starting work). The environment variable
// DRIFT_SIMD=sse2 caps it for a whole process.
class Limit {
 public:
  explicit Limit(Isa isa);
  ~Limit();
  Limit(const Limit&) = delete;
  Limit& operator=(const Limit&) = delete;

 private:
  Isa previous_;
};

}  // namespace drift::simd

// Defines `name` as a dispatcher between two compilations of `kernel` (a
// function declared DRIFT_SIMD_KERNEL, or a template instance of one) with
// the given parameter and argument lists: one for baseline x86-64, one for
// AVX2. Elsewhere (not x86-64 GCC/Clang) the kernel is called directly. Use
// it in an unnamed namespace.
//
// GCC vectorises a kernel's loops only if it knows its arrays do not overlap:
// give the kernel `__restrict` pointer parameters and write the loop in the
// kernel itself, not in a function or lambda it calls (restrict does not
// survive a second level of inlining or a capture by reference).
#ifdef DRIFT_SIMD_X86
#define DRIFT_SIMD_TWINS(name, kernel, params, args)               \
  [[gnu::target("avx2")]] void name##_avx2 params { kernel args; } \
  void name##_sse2 params { kernel args; }                         \
  void name params {                                               \
    if (::drift::simd::active() == ::drift::simd::Isa::Avx2) {     \
      name##_avx2 args;                                            \
    } else {                                                       \
      name##_sse2 args;                                            \
    }                                                              \
  }
#define DRIFT_SIMD_KERNEL [[gnu::always_inline]] inline
#else
#define DRIFT_SIMD_TWINS(name, kernel, params, args) \
  void name params { kernel args; }
#define DRIFT_SIMD_KERNEL inline
#endif
