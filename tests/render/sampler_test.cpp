// The sampler (render/sobol.h, render/random.h) against what makes it worth
// having: Joe & Kuo's direction numbers, the (0,m,2)-net property of every
// power-of-two run of a pixel's samples kept through Owen scrambling and the
// index shuffle (Burley 2020), integration error falling faster than
// independent random numbers can (Owen 1997: O(N^-1.5) on smooth
// integrands), decorrelated pixels and sets, determinism.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <set>
#include <vector>

#include "render/random.h"
#include "render/sobol.h"

using namespace drift::render;

namespace {

// True if the n = 2^m points have exactly one point in every elementary
// interval [a 2^-k, (a+1) 2^-k) x [b 2^-(m-k), (b+1) 2^-(m-k)), k = 0..m:
// a (0,m,2)-net in base 2.
bool is_02_net(const std::vector<std::array<float, 2>>& p, int m) {
  for (int k = 0; k <= m; ++k) {
    std::vector<int> count(std::size_t{1} << m, 0);
    for (const auto& q : p) {
      const auto a = static_cast<std::uint32_t>(q[0] * static_cast<float>(1u << k));
      const auto b = static_cast<std::uint32_t>(q[1] * static_cast<float>(1u << (m - k)));
      ++count[(a << (m - k)) | b];
    }
    for (int c : count)
      if (c != 1) return false;
  }
  return true;
}

// The first n samples of set `set` (1-based: the set-th call) of a pixel.
std::vector<std::array<float, 2>> pixel_points(std::uint64_t seed, std::uint64_t pixel, int set,
                                               int n) {
  std::vector<std::array<float, 2>> p;
  for (int i = 0; i < n; ++i) {
    SampleStream rng(seed, pixel, static_cast<std::uint64_t>(i));
    for (int s = 1; s < set; ++s) rng.next2d();
    p.push_back(rng.next2d());
  }
  return p;
}

// A smooth integrand over the unit square and its exact integral.
double smooth(double x, double y) {
  return std::exp(x) * (1.0 + std::sin(2.0 * std::numbers::pi * y));
}
const double kSmoothIntegral = std::numbers::e - 1.0;
// A discontinuous one: the quarter disc of radius 0.9, area pi 0.81 / 4.
double disc(double x, double y) { return x * x + y * y < 0.81 ? 1.0 : 0.0; }
const double kDiscIntegral = std::numbers::pi * 0.81 / 4.0;

// RMS error over `pixels` pixels of the n-sample estimate of f's integral
// drawn by `draw` (pixel, sample) -> point.
double rms_error(const std::function<double(double, double)>& f, double exact, int n, int pixels,
                 const std::function<std::array<float, 2>(int, int)>& draw) {
  double se = 0.0;
  for (int px = 0; px < pixels; ++px) {
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      const auto u = draw(px, i);
      sum += f(u[0], u[1]);
    }
    se += (sum / n - exact) * (sum / n - exact);
  }
  return std::sqrt(se / pixels);
}

std::array<float, 2> sobol_draw(int px, int i) {
  return SampleStream(1, static_cast<std::uint64_t>(px), static_cast<std::uint64_t>(i)).next2d();
}

// Independent hashed numbers, as the renderer drew before: the baseline.
std::array<float, 2> random_draw(int px, int i) {
  using drift::terrain::mix64;
  const std::uint64_t key =
      mix64(mix64(mix64(1) ^ static_cast<std::uint64_t>(px)) ^ static_cast<std::uint64_t>(i));
  return {drift::terrain::unit_float(mix64(key)), drift::terrain::unit_float(mix64(key ^ 1))};
}

}  // namespace

TEST(Sobol, MatricesAreJoeAndKuos) {
  // Columns k = 1..4 are m_k / 2^k with Joe & Kuo's m: d = 2: 1 3 5 15,
  // d = 3: 1 3 3 9, d = 4: 1 3 1 5 (the later ones by the recurrence).
  const std::uint32_t m[3][4] = {{1, 3, 5, 15}, {1, 3, 3, 9}, {1, 3, 1, 5}};
  for (int d = 1; d < sobol::kDimensions; ++d)
    for (int k = 0; k < 4; ++k)
      EXPECT_EQ(sobol::kMatrices[d][k], m[d - 1][k] << (31 - k))
          << "dimension " << d << " column " << k;
  // Column k (m_{k+1} odd, below 2^(k+1)) ends in digit k + 1: the matrix
  // is triangular with a unit diagonal, so each dimension alone is a
  // (0,1)-sequence.
  for (int d = 0; d < sobol::kDimensions; ++d)
    for (int k = 0; k < 32; ++k) EXPECT_EQ(std::countr_zero(sobol::kMatrices[d][k]), 31 - k);
  // Each dimension's shortcut (bits reversed, byte tables) is its matrix.
  for (int d = 0; d < sobol::kDimensions; ++d) {
    for (std::uint32_t i : {0u, 1u, 6u, 1234567u, 0x89abcdefu, 0xffffffffu}) {
      std::uint32_t x = 0;
      for (int k = 0; k < 32; ++k)
        if ((i >> k) & 1u) x ^= sobol::kMatrices[d][k];
      EXPECT_EQ(sobol::sample_bits(i, d), x) << "dimension " << d << " index " << i;
    }
  }
}

TEST(Sobol, FirstTwoDimensionsAreA02Sequence) {
  // Every aligned run of 2^m points is a (0,m,2)-net, unscrambled...
  for (int m = 1; m <= 10; ++m) {
    for (std::uint32_t block : {0u, 1u, 37u}) {
      std::vector<std::array<float, 2>> p;
      for (std::uint32_t i = 0; i < (1u << m); ++i) {
        const std::uint32_t index = (block << m) | i;
        p.push_back({sobol::to_unit_float(sobol::sample_bits(index, 0)),
                     sobol::to_unit_float(sobol::sample_bits(index, 1))});
      }
      EXPECT_TRUE(is_02_net(p, m)) << "m " << m << " block " << block;
    }
  }
  // ... and Owen-scrambled per coordinate with any seeds (Owen 1995).
  for (std::uint32_t seed : {1u, 0xdeadbeefu, 0x12345u}) {
    std::vector<std::array<float, 2>> p;
    for (std::uint32_t i = 0; i < 256; ++i)
      p.push_back({sobol::to_unit_float(sobol::owen_scramble(sobol::sample_bits(i, 0), seed)),
                   sobol::to_unit_float(sobol::owen_scramble(sobol::sample_bits(i, 1), ~seed))});
    EXPECT_TRUE(is_02_net(p, 8)) << "seed " << seed;
  }
}

TEST(Sampler, EveryPowerOfTwoPrefixOfAPixelIsA02Net) {
  // The samples a pixel takes first, shuffled and scrambled (Burley 2020):
  // any power-of-two prefix, in any set, for any pixel and seed, so an
  // adaptive pixel stopping at 16, 32 ... samples is stratified too.
  for (std::uint64_t pixel : {0ull, 1ull, 999ull})
    for (int set : {1, 2, 7})
      for (int m : {2, 4, 6, 8, 10})
        EXPECT_TRUE(is_02_net(pixel_points(3, pixel, set, 1 << m), m))
            << "pixel " << pixel << " set " << set << " m " << m;
  // A 4-D set's lens coordinates (2, 3) are each stratified alone.
  for (int d = 0; d < 4; ++d) {
    std::set<int> strata;
    for (int i = 0; i < 64; ++i)
      strata.insert(static_cast<int>(SampleStream(5, 42, i).next4d()[d] * 64.0f));
    EXPECT_EQ(strata.size(), 64u) << "coordinate " << d;
  }
}

TEST(Sampler, SmoothIntegralsConvergeFasterThanRandomNumbers) {
  // Owen-scrambled nets integrate smooth functions with RMS error
  // O(N^-1.5) (Owen 1997) against independent samples' O(N^-0.5).
  const int pixels = 256;
  const double sobol_64 = rms_error(smooth, kSmoothIntegral, 64, pixels, sobol_draw);
  const double sobol_1024 = rms_error(smooth, kSmoothIntegral, 1024, pixels, sobol_draw);
  const double random_64 = rms_error(smooth, kSmoothIntegral, 64, pixels, random_draw);
  const double slope = std::log(sobol_1024 / sobol_64) / std::log(16.0);
  std::printf("smooth: RMS error at 64 samples %.3g (random %.3g), at 1024 %.3g: slope %.2f\n",
              sobol_64, random_64, sobol_1024, slope);
  EXPECT_LT(slope, -1.3);
  EXPECT_LT(sobol_64, 0.1 * random_64);
  // A discontinuity caps the rate (O(N^-0.75) for an edge in 2-D), but the
  // sampler is never worse than random numbers.
  const double disc_sobol = rms_error(disc, kDiscIntegral, 64, pixels, sobol_draw);
  const double disc_random = rms_error(disc, kDiscIntegral, 64, pixels, random_draw);
  std::printf("disc: RMS error at 64 samples %.3g (random %.3g)\n", disc_sobol, disc_random);
  EXPECT_LT(disc_sobol, 0.5 * disc_random);
}

TEST(Sampler, PixelsAndSetsAreDecorrelated) {
  // Neighbouring pixels' errors are uncorrelated (each pixel's sequence is
  // shuffled and scrambled by its own seed), or the noise would form a
  // pattern across the image; likewise two sets of one sample.
  const int pixels = 2048, n = 16;
  std::vector<double> err(pixels);
  for (int px = 0; px < pixels; ++px) {
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      const auto u = sobol_draw(px, i);
      sum += disc(u[0], u[1]);
    }
    err[px] = sum / n - kDiscIntegral;
  }
  double c01 = 0.0, c00 = 0.0;
  for (int px = 0; px + 1 < pixels; ++px) c01 += err[px] * err[px + 1], c00 += err[px] * err[px];
  EXPECT_LT(std::abs(c01 / c00), 0.1) << "correlation of neighbouring pixels' errors";
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (int i = 0; i < 4096; ++i) {
    SampleStream rng(1, 7, static_cast<std::uint64_t>(i));
    const double x = rng.next2d()[0] - 0.5, y = rng.next2d()[0] - 0.5;
    sxy += x * y, sxx += x * x, syy += y * y;
  }
  EXPECT_LT(std::abs(sxy / std::sqrt(sxx * syy)), 0.05) << "correlation of sets 1 and 2";
}

TEST(Sampler, PureFunctionOfSeedPixelSampleAndSet) {
  SampleStream a(9, 123, 45), b(9, 123, 45);
  for (int s = 0; s < 20; ++s) {
    const auto x = a.next2d(), y = b.next2d();
    EXPECT_EQ(x, y);
    for (float v : x) {
      EXPECT_GE(v, 0.0f);
      EXPECT_LT(v, 1.0f);
    }
  }
  // A skipped set leaves the next one as it was; a 2-D draw is the first two
  // coordinates of the 4-D one (the pinhole and the thin lens agree).
  SampleStream drawn(9, 123, 45), skipped(9, 123, 45);
  drawn.next1d();
  skipped.skip();
  EXPECT_EQ(drawn.next2d(), skipped.next2d());
  const auto two = SampleStream(9, 123, 45).next2d();
  const auto four = SampleStream(9, 123, 45).next4d();
  EXPECT_EQ(two[0], four[0]);
  EXPECT_EQ(two[1], four[1]);
  EXPECT_NE(SampleStream(9, 123, 45).next2d(), SampleStream(10, 123, 45).next2d());
  EXPECT_NE(SampleStream(9, 123, 45).next2d(), SampleStream(9, 124, 45).next2d());
  EXPECT_NE(SampleStream(9, 123, 45).next2d(), SampleStream(9, 123, 46).next2d());
}
