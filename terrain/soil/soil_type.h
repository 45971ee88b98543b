// Soil properties for Li & Moshell's slippage (paper 004, sec. 2.1.2 and
// table 6, taken from Li & Moshell 1993):
//
// | type       | phi (deg) | c (t/m)   | gamma (t/m^2) | preset used here    |
// |------------|-----------|-----------|---------------|---------------------|
// | dry sand   | 26 - 33   | 0         | 1.9 - 2.0     | 30, 0,   1.95       |
// | sandy loam | 14 - 26   | 0 - 2.0   | 1.8 - 2.0     | 22, 0.2, 1.9        |
// | loam       | 10 - 28   | 0.5 - 5.0 | 1.8 - 2.1     | 20, 0.5, 2.0        |
//
// c is per metre of slice width, so c / gamma is a length: a cut stands
// vertical up to 4 c / gamma tan(45 + phi / 2) metres (Terzaghi; sandy loam
// 0.62 m, loam 1.43 m) and a taller slope stands flatter. The slippage tests
// failure over a pile's real height in metres (rest_angle, soil_slice.h), so
// this holds at any voxel size.
//
// Moisture (thesis 5.3.4): wet sand holds steeper slopes through capillary
// cohesion. Moisture in [0, 1] (0 dry, 1 damp through) is a per-voxel field
// carried with the soil (SoilState::wet); a pile's moisture m adds
// kMoistCohesion * m to c; the renderer's wet coat reads it as wetness.
// `moisture` here is the moisture soil starts with where the scenario gives
// none of its own.
#pragma once

#include <string>
#include <vector>

namespace drift::soil {

struct SoilType {
  std::string name = "dry_sand";
  // Ranges: terrain/soil/soil_parameters.toml.
  double phi_deg = 30.0;  // angle of internal friction, degrees
  double cohesion = 0.0;  // c, t/m
  double gamma = 1.95;    // specific weight, t/m^2
  double moisture = 0.0;  // initial moisture, 0 dry .. 1 wet
  // Water in the soil (issue 33, item 3; terrain/soil/drainage.h): the
  // saturated hydraulic conductivity K_s (m/s) that drains it down the
  // column, and the evaporation rate (m/s of water) at the exposed surface.
  double drainage = 5.83e-5;    // K_s, m/s (Rawls et al. 1982, sand)
  double evaporation = 5.8e-8;  // m/s = 5 mm a day (FAO-56 reference ET0, Allen et al. 1998)
  double campbell_b = 4.05;     // K = K_s S^(2b + 3) (Campbell 1974; b of Clapp & Hornberger 1978)
  double porosity = 0.395;      // saturated water content (Clapp & Hornberger 1978)

  // Apparent cohesion of moist sand, t/m at moisture 1 (about 3 kPa: the
  // order of the apparent cohesion suction gives damp sands, a few kPa; Lu &
  // Likos 2004, Unsaturated Soil Mechanics). Acting over the pile's height it
  // holds damp sand vertical up to about 1 m (a sand castle).
  static constexpr double kMoistCohesion = 0.3;
  double effective_cohesion(double m) const { return cohesion + kMoistCohesion * m; }
};

// The presets of table 6 ("dry_sand", "sandy_loam", "loam"); throws
// drift::Error listing the names for anything else.
SoilType soil_preset(const std::string& name);
std::vector<std::string> soil_preset_names();

}  // namespace drift::soil
