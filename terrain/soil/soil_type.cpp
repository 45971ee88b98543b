#include "terrain/soil/soil_type.h"

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

}  // namespace

SoilType soil_preset(const std::string& name) {
  for (const SoilType& s : kPresets)
    if (s.name == name) return s;
  throw Error("unknown soil type '" + name + "'; use dry_sand, sandy_loam or loam");
}

std::vector<std::string> soil_preset_names() { return {"dry_sand", "sandy_loam", "loam"}; }

}  // namespace drift::soil
