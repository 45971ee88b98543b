// Coverage (paper 003, 2.1(4) and 2.3(5)): thin snow's coverage rises with depth
// up to the thin-snow depth; stuck flakes grow with steepness, with facing the
// snowfall and with the amount that fell; and the jittered snowfall
// directions (2.1(2)) are weighted by the Gaussian of their angle from the mean.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "snow/adhesion_coverage.h"
#include "snow/snowfall_directions.h"

namespace {

using drift::snow::adhesion_coverage;
using drift::snow::CoverageOptions;
using drift::snow::thin_coverage;

Eigen::Vector3d normal_at(double slope_deg) {  // tilted towards +x
  const double a = slope_deg * std::numbers::pi / 180.0;
  return {std::sin(a), 0.0, std::cos(a)};
}

TEST(SnowCoverage, ThinSnowCoverageRisesWithDepthUpToTheThinDepth) {
  CoverageOptions o;
  o.thin_depth = 0.04;
  EXPECT_EQ(thin_coverage(0.0, o), 0.0);
  EXPECT_NEAR(thin_coverage(0.01, o), 0.25, 1e-12);
  EXPECT_NEAR(thin_coverage(0.03, o), 0.75, 1e-12);
  EXPECT_EQ(thin_coverage(0.04, o), 1.0);
  EXPECT_EQ(thin_coverage(2.0, o), 1.0);
  EXPECT_EQ(thin_coverage(-1e-17, o), 0.0);  // rounding below zero
}

TEST(SnowCoverage, StuckFlakesNeedASteepFaceFacingTheSnowAndSomeSnowfall) {
  CoverageOptions o;  // adhesion 0.6 from 60 degrees, 5 cm for 63 %
  const double lots = 10.0;
  EXPECT_EQ(adhesion_coverage(normal_at(0.0), 1.0, lots, o), 0.0);            // flat: none
  EXPECT_EQ(adhesion_coverage(normal_at(55.0), 1.0, lots, o), 0.0);           // below min slope
  EXPECT_NEAR(adhesion_coverage(normal_at(75.0), 1.0, lots, o), 0.3, 1e-9);   // half way
  EXPECT_NEAR(adhesion_coverage(normal_at(90.0), 1.0, lots, o), 0.6, 1e-9);   // wall
  EXPECT_NEAR(adhesion_coverage(normal_at(135.0), 1.0, lots, o), 0.6, 1e-9);  // overhang
  // Proportional to how much the face faces the snowfall; none in the lee.
  EXPECT_NEAR(adhesion_coverage(normal_at(90.0), 0.5, lots, o), 0.3, 1e-9);
  EXPECT_EQ(adhesion_coverage(normal_at(90.0), 0.0, lots, o), 0.0);
  // Saturating with the amount: 1 - exp(-amount / adhesion_depth).
  EXPECT_NEAR(adhesion_coverage(normal_at(90.0), 1.0, 0.05, o), 0.6 * (1 - std::exp(-1.0)), 1e-9);
  EXPECT_LT(adhesion_coverage(normal_at(90.0), 1.0, 0.01, o),
            adhesion_coverage(normal_at(90.0), 1.0, 0.05, o));
}

TEST(SnowfallDirections, WeightsFollowTheGaussianOfTheirAngle) {
  const double spread = 8.0, sigma = spread * std::numbers::pi / 180.0;
  const auto dirs = drift::snow::jittered_directions(300.0, 60.0, spread, 16, 3);
  const Eigen::Vector3d mean =
      drift::snow::jittered_directions(300.0, 60.0, 0.0, 1, 3)[0].toward_source;
  double total = 0.0, norm = 0.0;
  for (const auto& d : dirs) norm += std::exp(-d.angle_rad * d.angle_rad / (2 * sigma * sigma));
  for (const auto& d : dirs) {
    // The recorded angle is the true angle from the mean direction ...
    EXPECT_NEAR(std::acos(std::clamp(d.toward_source.dot(mean), -1.0, 1.0)), d.angle_rad, 1e-9);
    // ... and the weight its normalised Gaussian.
    EXPECT_NEAR(d.weight, std::exp(-d.angle_rad * d.angle_rad / (2 * sigma * sigma)) / norm, 1e-6);
    EXPECT_LE(d.angle_rad, 2.5 * sigma + 1e-12);
    total += d.weight;
  }
  EXPECT_NEAR(total, 1.0, 1e-6);
  // Directions nearer the mean weigh more.
  for (const auto& a : dirs)
    for (const auto& b : dirs)
      if (a.angle_rad < b.angle_rad - 1e-9) {
        EXPECT_GT(a.weight, b.weight);
      }
}

}  // namespace
