// The sun's position from date, time and place: NOAA's solar calculator
// (Global Monitoring Laboratory, "NOAA Solar Calculator" and its spreadsheet
// NOAA_Solar_Calculations_day.xls, after Meeus, "Astronomical Algorithms",
// 1991). Stated accuracy: about 1 arc-minute for 1800-2100 at latitudes within
// +-72 degrees; apparent elevation with NOAA's refraction correction.
#pragma once

#include <string>

namespace drift::render {

// A civil date and time with its offset from UTC.
struct LocalTime {
  int year = 2000, month = 1, day = 1;
  int hour = 12, minute = 0;
  double second = 0.0;
  double utc_offset_hours = 0.0;  // e.g. +9 for Japan, -7 for PDT
};

// Parses "YYYY-MM-DD", "HH:MM" or "HH:MM:SS" and an offset "+09:00", "-07:00",
// "+0530", "+9", "Z" or "UTC". Throws drift::Error naming the bad value.
LocalTime parse_local_time(const std::string& date, const std::string& time,
                           const std::string& utc_offset);

// Julian day (UT) of a local time (Meeus 1991, ch. 7, Gregorian calendar).
double julian_day(const LocalTime& t);

struct SolarPosition {
  double azimuth_deg = 0;         // clockwise from true north, [0, 360)
  double elevation_deg = 0;       // apparent: with atmospheric refraction
  double true_elevation_deg = 0;  // geometric
  double declination_deg = 0;
  double equation_of_time_min = 0;
};

// Latitude north and longitude east, degrees.
SolarPosition solar_position(const LocalTime& t, double latitude_deg, double longitude_deg);

}  // namespace drift::render
