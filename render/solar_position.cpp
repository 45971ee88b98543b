#include "render/solar_position.h"

#include <algorithm>
#include <cmath>
#include <regex>

#include "terrain/angles.h"
#include "terrain/error.h"

namespace drift::render {

namespace {

constexpr double kDeg = terrain::kRadiansPerDegree<double>;

bool leap(int y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

int days_in_month(int y, int m) {
  static const int days[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return m == 2 && leap(y) ? 29 : days[m - 1];
}

// NOAA's refraction correction (spreadsheet column AE), degrees, for a true
// elevation in degrees.
double refraction_deg(double e) {
  if (e > 85.0) return 0.0;
  const double t = std::tan(e * kDeg);
  double arcsec;
  if (e > 5.0) {
    arcsec = 58.1 / t - 0.07 / (t * t * t) + 0.000086 / std::pow(t, 5);
  } else if (e > -0.575) {
    arcsec = 1735.0 + e * (-518.2 + e * (103.4 + e * (-12.79 + e * 0.711)));
  } else {
    arcsec = -20.772 / t;
  }
  return arcsec / 3600.0;
}

double wrap360(double a) {
  a = std::fmod(a, 360.0);
  return a < 0.0 ? a + 360.0 : a;
}

}  // namespace

LocalTime parse_local_time(const std::string& date, const std::string& time,
                           const std::string& utc_offset) {
  LocalTime t;
  std::smatch m;
  if (!std::regex_match(date, m, std::regex(R"((\d{4})-(\d{2})-(\d{2}))"))) {
    throw Error("date '" + date + "' must be YYYY-MM-DD, e.g. \"2024-03-20\"");
  }
  t.year = std::stoi(m[1]);
  t.month = std::stoi(m[2]);
  t.day = std::stoi(m[3]);
  if (t.month < 1 || t.month > 12 || t.day < 1 || t.day > days_in_month(t.year, t.month)) {
    throw Error("date '" + date + "' is not a calendar date");
  }
  if (!std::regex_match(time, m, std::regex(R"((\d{1,2}):(\d{2})(?::(\d{2}(?:\.\d+)?))?)"))) {
    throw Error("time '" + time + "' must be HH:MM or HH:MM:SS (24-hour local time)");
  }
  t.hour = std::stoi(m[1]);
  t.minute = std::stoi(m[2]);
  t.second = m[3].matched ? std::stod(m[3]) : 0.0;
  if (t.hour > 23 || t.minute > 59 || t.second >= 60.0) {
    throw Error("time '" + time + "' is out of range (00:00 to 23:59:59)");
  }
  if (utc_offset == "Z" || utc_offset == "UTC") {
    t.utc_offset_hours = 0.0;
  } else if (std::regex_match(utc_offset, m, std::regex(R"(([+-])(\d{1,2})(?::?(\d{2}))?)"))) {
    const double h = std::stoi(m[2]) + (m[3].matched ? std::stoi(m[3]) / 60.0 : 0.0);
    if (h > 14.0) throw Error("timezone '" + utc_offset + "' is beyond +-14:00");
    t.utc_offset_hours = m[1] == "-" ? -h : h;
  } else {
    throw Error("timezone '" + utc_offset +
                "' must be an offset from UTC such as \"+09:00\", \"-07:00\" or \"Z\" (IANA "
                "names like Asia/Tokyo are not supported)");
  }
  return t;
}

double julian_day(const LocalTime& t) {
  int y = t.year, m = t.month;
  if (m <= 2) {
    y -= 1;
    m += 12;
  }
  const int a = y / 100;
  const int b = 2 - a + a / 4;
  const double day_fraction =
      (t.hour + t.minute / 60.0 + t.second / 3600.0 - t.utc_offset_hours) / 24.0;
  return std::floor(365.25 * (y + 4716)) + std::floor(30.6001 * (m + 1)) + t.day + b - 1524.5 +
         day_fraction;
}

SolarPosition solar_position(const LocalTime& t, double latitude_deg, double longitude_deg) {
  // NOAA spreadsheet, columns G to AH, in order.
  const double jc = (julian_day(t) - 2451545.0) / 36525.0;  // Julian century
  const double l0 = wrap360(280.46646 + jc * (36000.76983 + jc * 0.0003032));
  const double m = 357.52911 + jc * (35999.05029 - 0.0001537 * jc);
  const double e = 0.016708634 - jc * (0.000042037 + 0.0000001267 * jc);
  const double c = std::sin(m * kDeg) * (1.914602 - jc * (0.004817 + 0.000014 * jc)) +
                   std::sin(2 * m * kDeg) * (0.019993 - 0.000101 * jc) +
                   std::sin(3 * m * kDeg) * 0.000289;
  const double true_long = l0 + c;
  const double omega = 125.04 - 1934.136 * jc;
  const double app_long = true_long - 0.00569 - 0.00478 * std::sin(omega * kDeg);
  const double obliq0 =
      23.0 + (26.0 + (21.448 - jc * (46.815 + jc * (0.00059 - jc * 0.001813))) / 60.0) / 60.0;
  const double obliq = obliq0 + 0.00256 * std::cos(omega * kDeg);
  const double decl = std::asin(std::sin(obliq * kDeg) * std::sin(app_long * kDeg)) / kDeg;
  const double y = std::pow(std::tan(obliq * kDeg / 2.0), 2);
  const double eot =
      4.0 / kDeg *
      (y * std::sin(2 * l0 * kDeg) - 2 * e * std::sin(m * kDeg) +
       4 * e * y * std::sin(m * kDeg) * std::cos(2 * l0 * kDeg) -
       0.5 * y * y * std::sin(4 * l0 * kDeg) - 1.25 * e * e * std::sin(2 * m * kDeg));
  const double local_minutes = t.hour * 60.0 + t.minute + t.second / 60.0;
  const double true_solar_time =
      std::fmod(local_minutes + eot + 4.0 * longitude_deg - 60.0 * t.utc_offset_hours, 1440.0);
  const double tst = true_solar_time < 0 ? true_solar_time + 1440.0 : true_solar_time;
  const double hour_angle = tst / 4.0 < 0 ? tst / 4.0 + 180.0 : tst / 4.0 - 180.0;
  const double lat = latitude_deg * kDeg, dec = decl * kDeg, ha = hour_angle * kDeg;
  const double cos_zenith =
      std::sin(lat) * std::sin(dec) + std::cos(lat) * std::cos(dec) * std::cos(ha);
  const double zenith = std::acos(std::clamp(cos_zenith, -1.0, 1.0)) / kDeg;
  SolarPosition out;
  out.true_elevation_deg = 90.0 - zenith;
  out.elevation_deg = out.true_elevation_deg + refraction_deg(out.true_elevation_deg);
  // Clockwise from north (the spreadsheet's acos form, written with atan2).
  out.azimuth_deg = wrap360(
      std::atan2(std::sin(ha), std::cos(ha) * std::sin(lat) - std::tan(dec) * std::cos(lat)) /
          kDeg +
      180.0);
  out.declination_deg = decl;
  out.equation_of_time_min = eot;
  return out;
}

}  // namespace drift::render
