#include "terrain/soil/soil_type.h"

#include "terrain/error.h"

namespace drift::soil {

namespace {
// The middle of table 6's ranges (dry sand's 30 degrees is also the middle of
// the measured angle of repose of dry sand, 30-35 degrees). Water: K_s of
// Rawls, Brakensiek & Saxton 1982 (Trans. ASAE 25, table 2: 21.0, 2.59 and
// 1.32 cm/h), Campbell's b and the porosity of Clapp & Hornberger 1978 (Water
// Resour. Res. 14, table 2), evaporation 5 mm a day (FAO-56).
const SoilType kPresets[] = {
    {"dry_sand", 30.0, 0.0, 1.95, 0.0, 5.83e-5, 5.8e-8, 4.05, 0.395},
    {"sandy_loam", 22.0, 0.2, 1.9, 0.0, 7.19e-6, 5.8e-8, 4.90, 0.435},
    {"loam", 20.0, 0.5, 2.0, 0.0, 3.67e-6, 5.8e-8, 5.39, 0.451},
};

}  // namespace

SoilType soil_preset(const std::string& name) {
  for (const SoilType& s : kPresets)
    if (s.name == name) return s;
  throw Error("unknown soil type '" + name + "'; use dry_sand, sandy_loam or loam");
}

std::vector<std::string> soil_preset_names() { return {"dry_sand", "sandy_loam", "loam"}; }

}  // namespace drift::soil
