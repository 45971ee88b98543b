#include "render/fast_math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace drift::render {
namespace {

TEST(FastMath, Atan2MatchesLibmAroundTheCircleAtEveryScale) {
  // Every octant and both reductions of the kernel, at lengths from 1e-30
  // to 1e30 (the ratio is formed without overflow), against double atan2.
  double worst = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const double a = -std::numbers::pi + 2.0 * std::numbers::pi * (i + 0.37) / 20000.0;
    for (const double r : {1e-30, 1e-3, 1.0, 7.0, 1e30}) {
      const auto x = static_cast<float>(r * std::cos(a)), y = static_cast<float>(r * std::sin(a));
      worst = std::max(worst, std::abs(fast_atan2(y, x) -
                                       std::atan2(static_cast<double>(y), static_cast<double>(x))));
    }
  }
  EXPECT_LT(worst, 5e-7);
  // The axes and the origin.
  EXPECT_EQ(fast_atan2(0.0f, 0.0f), 0.0f);
  EXPECT_NEAR(fast_atan2(1.0f, 0.0f), std::numbers::pi / 2, 2e-7);
  EXPECT_NEAR(fast_atan2(-1.0f, 0.0f), -std::numbers::pi / 2, 2e-7);
  EXPECT_NEAR(fast_atan2(0.0f, -1.0f), std::numbers::pi, 3e-7);
  EXPECT_EQ(fast_atan2(0.0f, 1.0f), 0.0f);
}

TEST(FastMath, AsinAndAcosMatchLibmAndClamp) {
  double worst = 0.0;
  for (int i = 0; i <= 200000; ++i) {
    const float z = -1.0f + 2.0f * static_cast<float>(i) / 200000.0f;
    worst = std::max(worst, std::abs(fast_asin(z) - std::asin(static_cast<double>(z))));
    worst = std::max(worst, std::abs(fast_acos(z) - std::acos(static_cast<double>(z))));
  }
  EXPECT_LT(worst, 5e-7);
  EXPECT_NEAR(fast_asin(1.5f), std::numbers::pi / 2, 2e-7);
  EXPECT_NEAR(fast_acos(-1.5f), std::numbers::pi, 3e-7);
  EXPECT_TRUE(std::isnan(fast_atan_positive(std::numeric_limits<float>::quiet_NaN())));
}

}  // namespace
}  // namespace drift::render
