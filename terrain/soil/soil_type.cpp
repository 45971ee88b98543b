#include "terrain/soil/soil_type.h"

#include <cmath>

#include "terrain/error.h"

namespace drift::soil {

namespace {
// The middle of table 6's ranges (dry sand's 30 degrees is also the middle of
// the measured angle of repose of dry sand, 30-35 degrees).
const SoilType kPresets[] = {
    {"dry_sand", 30.0, 0.0, 1.95, 0.0},
    {"sandy_loam", 22.0, 0.2, 1.9, 0.0},
    {"loam", 20.0, 0.5, 2.0, 0.0},
};

void check(bool ok, const std::string& field, double v, const std::string& range) {
  if (!ok) throw Error("soil " + field + " is " + std::to_string(v) + "; it must lie in " + range);
}
}  // namespace

SoilType soil_preset(const std::string& name) {
  for (const SoilType& s : kPresets)
    if (s.name == name) return s;
  throw Error("unknown soil type '" + name + "'; use dry_sand, sandy_loam or loam");
}

std::vector<std::string> soil_preset_names() { return {"dry_sand", "sandy_loam", "loam"}; }

void validate(const SoilType& s) {
  check(std::isfinite(s.phi_deg) && s.phi_deg >= 0 && s.phi_deg < 60, "phi (degrees)", s.phi_deg,
        "[0, 60)");
  check(std::isfinite(s.cohesion) && s.cohesion >= 0 && s.cohesion <= 20, "cohesion c (t/m)",
        s.cohesion, "[0, 20]");
  check(std::isfinite(s.gamma) && s.gamma > 0 && s.gamma <= 10, "specific weight gamma (t/m^2)",
        s.gamma, "(0, 10]");
  check(std::isfinite(s.moisture) && s.moisture >= 0 && s.moisture <= 1, "moisture", s.moisture,
        "[0, 1]");
}

}  // namespace drift::soil
