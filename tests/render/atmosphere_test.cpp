// The physical atmosphere against published values and against brute force:
// Rayleigh coefficients, zenith transmittance, the setting sun's colour, the
// precomputed tables, and the limits of aerial perspective.
#include "render/atmosphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "render/physical_sky.h"
#include "render/tonemap.h"
#include "terrain/error.h"

using namespace drift::render;

namespace {

const Atmosphere& atmosphere() {
  static const Atmosphere a;  // precomputation shared by the tests
  return a;
}

Eigen::Vector3d from_az_el(double az_deg, double el_deg) {
  const double az = az_deg * std::numbers::pi / 180, el = el_deg * std::numbers::pi / 180;
  return {std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el)};
}

}  // namespace

TEST(Atmosphere, RayleighScatteringMatchesBrunetonAndHillaire) {
  // Bruneton 2017 (precomputed_atmospheric_scattering, demo) and Hillaire 2020
  // (table 1): 5.802, 13.558, 33.1 x 1e-6 per metre at 680, 550, 440 nm.
  EXPECT_NEAR(Atmosphere::rayleigh_coefficient(680.0), 5.802e-6, 0.002e-6);
  EXPECT_NEAR(Atmosphere::rayleigh_coefficient(550.0), 13.558e-6, 0.002e-6);
  EXPECT_NEAR(Atmosphere::rayleigh_coefficient(440.0), 33.1e-6, 0.01e-6);
}

TEST(Atmosphere, ZenithTransmittanceAtSeaLevel) {
  // Bruneton's reference parameters, recomputed by hand: optical depth =
  // Rayleigh beta x 8 km + Mie 4.44e-6 x 1.2 km + ozone cross section x 300 DU
  // (8.061e22 m^-2): at 680 nm 0.0464 + 0.0053 + 0.0097 -> T = 0.940; at
  // 550 nm 0.1085 + 0.0053 + 0.0282 -> 0.868; at 440 nm 0.2648 + 0.0053 +
  // 0.0013 -> 0.762.
  const Atmosphere& a = atmosphere();
  EXPECT_NEAR(std::exp(-a.optical_depth_to_space(680.0, 0.0, 1.0)), 0.940, 0.002);
  EXPECT_NEAR(std::exp(-a.optical_depth_to_space(550.0, 0.0, 1.0)), 0.868, 0.002);
  EXPECT_NEAR(std::exp(-a.optical_depth_to_space(440.0, 0.0, 1.0)), 0.762, 0.002);
  // Below the horizon from the ground: the planet blocks the way.
  EXPECT_TRUE(std::isinf(a.optical_depth_to_space(550.0, 0.0, -0.1)));
}

TEST(Atmosphere, TheSunReddensAsItSets) {
  const Atmosphere& a = atmosphere();
  double previous_ratio = 0.0, previous_luminance = 1e9;
  for (double el : {90.0, 60.0, 30.0, 10.0, 5.0, 2.0}) {
    const Eigen::Vector3f c = a.sun_rgb(a.transmittance_to_space(0.0, std::sin(el * M_PI / 180)));
    const double ratio = c.x() / std::max(c.z(), 1e-6f);
    const double luminance = 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z();
    EXPECT_GT(ratio, previous_ratio) << "elevation " << el;
    EXPECT_LT(luminance, previous_luminance) << "elevation " << el;
    previous_ratio = ratio;
    previous_luminance = luminance;
  }
  EXPECT_GT(previous_ratio, 5.0);  // at 2 degrees the sun is deep orange-red
}

TEST(Atmosphere, TablesAgreeWithBruteForce) {
  const Atmosphere& a = atmosphere();
  // Transmittance table vs direct integration, off the table's grid; away
  // from the horizon's discontinuity: within 1 % (and 2e-4 where nearly opaque).
  for (double h : {0.0, 730.0, 2900.0, 8100.0}) {
    for (double mu : {-0.8, 0.07, 0.33, 0.91}) {
      const Spectrum table = a.transmittance_to_space(h, mu);
      const Spectrum exact = a.transmittance_to_space_exact(h, mu);
      for (int b = 0; b < kBands; ++b)
        EXPECT_NEAR(table[b], exact[b], 0.01 * exact[b] + 2e-4) << h << " " << mu << " " << b;
    }
  }
  // Sky-view table vs a 400-step march in a few directions: within 3 %.
  const Eigen::Vector3d sun = from_az_el(135.0, 25.0);
  const PhysicalSky sky(a, 1500.0, sun, 1.0f, 50000.0);
  for (auto [az, el] : {std::pair{0.0, 10.0}, std::pair{135.0, 40.0}, std::pair{250.0, 70.0},
                        std::pair{300.0, 3.0}}) {
    const Eigen::Vector3d d = from_az_el(az, el);
    const Eigen::Vector3f table = sky.sky(d.cast<float>());
    Spectrum t;
    const Eigen::Vector3f exact = a.radiance_to_rgb(a.in_scattering(1500.0, d, 1e9, sun, 400, &t));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(table[c], exact[c], 0.03 * exact[c]) << az << " " << el;
  }
}

TEST(AerialPerspective, FarBlackObjectTakesTheSkysColour) {
  const Atmosphere& a = atmosphere();
  const Eigen::Vector3d sun = from_az_el(180.0, 30.0);
  const PhysicalSky sky(a, 500.0, sun, 1.0f, 400000.0);
  const Eigen::Vector3f dir = from_az_el(90.0, 1.0).cast<float>();
  float previous = 0.0f, previous_t = 2.0f;
  for (float d : {1000.0f, 10000.0f, 50000.0f, 150000.0f, 400000.0f}) {
    const AirSegment seg = sky.from_camera(dir, d);
    EXPECT_GT(seg.inscatter.y(), previous) << d;  // more air, more light
    EXPECT_LT(seg.transmittance.y(), previous_t) << d;
    previous = seg.inscatter.y();
    previous_t = seg.transmittance.y();
  }
  // Far away a black object looks like the sky behind it (within 5 %), and
  // the blue channel leads: distant ridges turn blue.
  const AirSegment far = sky.from_camera(dir, 400000.0f);
  const Eigen::Vector3f behind = sky.sky(dir);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(far.inscatter[c], behind[c], 0.05 * behind[c]) << c;
  const AirSegment mid = sky.from_camera(dir, 20000.0f);
  EXPECT_GT(mid.inscatter.z(), mid.inscatter.x());
}

TEST(AerialPerspective, ShortHorizontalPathFollowsBeerLambert) {
  // 2 km at constant altitude (Earth's curvature lifts the end by 0.3 m):
  // T = exp(-extinction(h) x L) at every band, within 0.1 %.
  const Atmosphere& a = atmosphere();
  const double h = 1200.0, length = 2000.0;
  Spectrum t;
  a.in_scattering(h, Eigen::Vector3d(1.0, 0.0, 0.0), length, from_az_el(0.0, 40.0), 64, &t);
  const Spectrum ext = a.extinction(h);
  for (int b = 0; b < kBands; ++b) EXPECT_NEAR(t[b], std::exp(-ext[b] * length), 1e-3) << b;
}

TEST(Atmosphere, DaylightWhiteBalanceIsTheLevelLightOfTheSunSixtyDegreesUp) {
  // kDaylightWhiteBalance (render/tonemap.h) is a constant so that PNGs need
  // no atmosphere; it must stay the gains that make a white level surface at
  // sea level, under the sun 60 degrees up and its sky in Bruneton's reference
  // atmosphere, read neutral at unchanged luminance.
  const PhysicalSky air(atmosphere(), 0.0, from_az_el(180, 60), 1.0f, 1000.0);
  const Eigen::Vector3f e = air.level_irradiance();
  const float luminance = 0.2126f * e.x() + 0.7152f * e.y() + 0.0722f * e.z();
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(kDaylightWhiteBalance[c], luminance / e[c], 1e-3) << "channel " << c;
  // Daylight is warmer than the sRGB white (D65) with the sun this low: red
  // is turned down, blue up.
  EXPECT_LT(kDaylightWhiteBalance[0], 1.0f);
  EXPECT_GT(kDaylightWhiteBalance[2], 1.0f);
}

TEST(Atmosphere, VisibilityFollowsKoschmieder) {
  // Koschmieder: at the meteorological visibility V a black object keeps
  // exp(-3.912) = 2 % contrast: sea-level extinction at 550 nm (log-linear
  // between the 540 and 570 nm bands) is 3.912 / V, for a hazy 10 km and a
  // clear 60 km day.
  for (double km : {10.0, 60.0}) {
    AtmosphereParameters p;
    p.aerosol_scale = Atmosphere::aerosol_scale_for_visibility(km);
    const Atmosphere hazy(p);
    const Spectrum e = hazy.extinction(0.0);
    ASSERT_DOUBLE_EQ(Atmosphere::wavelength_nm(6), 540.0);
    const double at_550 = std::exp(std::log(e[6]) + (std::log(e[7]) - std::log(e[6])) / 3.0);
    EXPECT_NEAR(at_550 * km * 1000.0, 3.912, 0.01 * 3.912) << km << " km";
  }
  // And along a real 10 km line of sight at sea level (Earth's curvature
  // lifts its end by 8 m only): 2 % transmittance either side of 550 nm.
  AtmosphereParameters p;
  p.aerosol_scale = Atmosphere::aerosol_scale_for_visibility(10.0);
  const Atmosphere hazy(p);
  Spectrum t{};
  hazy.in_scattering(0.0, Eigen::Vector3d(1, 0, 0), 10000.0, from_az_el(0, 30), 256, &t);
  EXPECT_NEAR(t[6], 0.02, 0.002);
  EXPECT_NEAR(t[7], 0.02, 0.002);
  EXPECT_THROW(Atmosphere::aerosol_scale_for_visibility(400.0), drift::Error);
}
