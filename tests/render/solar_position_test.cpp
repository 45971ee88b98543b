// NOAA's solar position against published values.
#include "render/solar_position.h"

#include <gtest/gtest.h>

#include "terrain/error.h"

using namespace drift::render;

TEST(SolarPosition, NrelSpaExample) {
  // Reda & Andreas, "Solar Position Algorithm for Solar Radiation Applications",
  // NREL/TP-560-34302 (rev. 2008), the worked example: Golden, Colorado,
  // 39.742476 N 105.1786 W, 2003-10-17 12:30:30 at UTC-7: topocentric zenith
  // 50.11162 degrees (with refraction), azimuth 194.34024 degrees. SPA is good
  // to 0.0003 degrees; NOAA's calculator to about 1 arc-minute, so 0.05.
  const LocalTime t = parse_local_time("2003-10-17", "12:30:30", "-07:00");
  const SolarPosition s = solar_position(t, 39.742476, -105.1786);
  EXPECT_NEAR(90.0 - s.elevation_deg, 50.11162, 0.05);
  EXPECT_NEAR(s.azimuth_deg, 194.34024, 0.05);
}

TEST(SolarPosition, NoaaCalculatorHelsinki) {
  // NOAA Solar Calculator values quoted in "Testing solar calculator in Elm"
  // (discourse.elm-lang.org/t/8628): Helsinki 60.17 N 24.94 E, 2022-09-04
  // 13:19:29 at UTC+3 (NOAA's solar noon): refraction-corrected elevation
  // 36.96, azimuth 180.05, declination 7.11 degrees (printed to 0.01).
  const LocalTime t = parse_local_time("2022-09-04", "13:19:29", "+03:00");
  const SolarPosition s = solar_position(t, 60.17, 24.94);
  EXPECT_NEAR(s.elevation_deg, 36.96, 0.01);
  EXPECT_NEAR(s.azimuth_deg, 180.05, 0.01);
  EXPECT_NEAR(s.declination_deg, 7.11, 0.01);
}

TEST(SolarPosition, EquinoxAndSolsticeDeclination) {
  // US Naval Observatory, "Earth's Seasons" 2024: March equinox 2024-03-20
  // 03:06 UT, June solstice 2024-06-20 20:51 UT. The declination is 0 at the
  // equinox and the obliquity (23.44 degrees) at the solstice.
  EXPECT_NEAR(solar_position(parse_local_time("2024-03-20", "03:06", "Z"), 0, 0).declination_deg,
              0.0, 0.01);
  EXPECT_NEAR(solar_position(parse_local_time("2024-06-20", "20:51", "Z"), 0, 0).declination_deg,
              23.44, 0.01);
  // The same instant written in two time zones is the same sun.
  const SolarPosition a =
      solar_position(parse_local_time("2024-06-21", "05:51", "+09:00"), 36, 137);
  const SolarPosition b = solar_position(parse_local_time("2024-06-20", "20:51", "Z"), 36, 137);
  EXPECT_NEAR(a.azimuth_deg, b.azimuth_deg, 1e-9);
  EXPECT_NEAR(a.elevation_deg, b.elevation_deg, 1e-9);
}

TEST(SolarPosition, JulianDayOfMeeus) {
  // Meeus 1991, example 7.a: 1957 October 4.81 -> JD 2436116.31.
  const LocalTime t{.year = 1957, .month = 10, .day = 4, .hour = 19, .minute = 26, .second = 24.0};
  EXPECT_NEAR(julian_day(t), 2436116.31, 1e-6);
}

TEST(SolarPosition, BadInputsAreErrors) {
  EXPECT_THROW(parse_local_time("2024-02-30", "12:00", "Z"), drift::Error);
  EXPECT_THROW(parse_local_time("20240320", "12:00", "Z"), drift::Error);
  EXPECT_THROW(parse_local_time("2024-03-20", "25:00", "Z"), drift::Error);
  EXPECT_THROW(parse_local_time("2024-03-20", "12:00", "Asia/Tokyo"), drift::Error);
  EXPECT_NO_THROW(parse_local_time("2024-02-29", "23:59:59", "+0530"));
}
