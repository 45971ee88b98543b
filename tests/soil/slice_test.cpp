// Li & Moshell's slice (paper 004, eqs. 1-10) against closed forms.
#include <gtest/gtest.h>

#include <cmath>

#include "terrain/soil/soil_slice.h"

namespace drift::soil {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The failure plane has F = 1 (eq. 4), lies between phi and the slope, and
// the planes just above it fail (F < 1).
TEST(SoilSlice, FailurePlaneHasFactorOfSafetyOne) {
  for (double c : {0.0, 0.05, 0.2})
    for (double phi : {20.0, 30.0})
      for (double h : {0.2, 0.5, 1.0}) {
        const auto theta = failure_plane(h, 0.1, c, phi * kDeg, 2.0);
        if (!theta) continue;
        EXPECT_GE(*theta, phi * kDeg - 1e-12);
        EXPECT_LT(*theta, std::atan(h / 0.1));
        if (c > 0) {
          EXPECT_NEAR(factor_of_safety(h, 0.1, *theta, c, phi * kDeg, 2.0), 1.0, 1e-9);
        }
        EXPECT_LT(factor_of_safety(h, 0.1, *theta + 1e-3, c, phi * kDeg, 2.0), 1.0);
      }
}

// Cohesionless soil fails on the plane at phi; slopes at or below phi stand.
TEST(SoilSlice, CohesionlessSoilFailsAtTheFrictionAngle) {
  EXPECT_NEAR(*failure_plane(0.1, 0.1, 0.0, 30 * kDeg, 2.0), 30 * kDeg, 1e-12);
  EXPECT_FALSE(failure_plane(0.1 * std::tan(29.9 * kDeg), 0.1, 0.0, 30 * kDeg, 2.0));
  EXPECT_FALSE(failure_plane(0.0, 0.1, 0.0, 30 * kDeg, 2.0));
}

// Cohesion holds a slope that friction alone would not: a 60 degree slope of
// 10 cm voxels fails without c and stands with c = 0.5 t/m (loam), as a cut
// in loam stands vertical up to 4 c / gamma tan(45 + phi / 2) ~ 1.4 m.
TEST(SoilSlice, CohesionHoldsSteepSlopes) {
  const double h = 0.1 * std::tan(60 * kDeg);
  EXPECT_TRUE(failure_plane(h, 0.1, 0.0, 20 * kDeg, 2.0));
  EXPECT_FALSE(failure_plane(h, 0.1, 0.5, 20 * kDeg, 2.0));
  // For every plane of the slope, F >= 1 then.
  for (double t = 0.01; t < 60 * kDeg; t += 0.01)
    EXPECT_GE(factor_of_safety(h, 0.1, t, 0.5, 20 * kDeg, 2.0), 1.0) << t;
}

// Eq. 8: the net force drives the wedge down the slope and grows with the
// rise; at h = tan(theta) dx (no wedge) it vanishes.
TEST(SoilSlice, NetForceGrowsWithTheWedge) {
  const double dx = 0.1, gamma = 2.0, theta = 35 * kDeg;
  EXPECT_NEAR(net_force(std::tan(theta) * dx, dx, theta, gamma), 0.0, 1e-15);
  double last = 0;
  for (double h = 0.08; h < 0.5; h += 0.04) {
    const double f = net_force(h, dx, theta, gamma);
    EXPECT_GT(f, last) << h;
    last = f;
  }
}

// Eq. 10: what moves is the wedge's height times v dt / dx.
TEST(SoilSlice, TransferredHeight) {
  EXPECT_NEAR(transferred_height(0.3, 0.1, std::atan(1.0), 0.5, 0.02),
              (0.3 - 0.1) * 0.5 * 0.02 / 0.1, 1e-15);
}

}  // namespace
}  // namespace drift::soil
