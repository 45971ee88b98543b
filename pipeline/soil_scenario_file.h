// Reading soil scenario files (TOML; keys in docs/soil.md) into a
// soil::SoilScenario. Every value is checked, unknown keys are errors, paths
// are relative to the file.
#pragma once

#include <filesystem>

#include "terrain/soil/scenario.h"

namespace drift::pipeline {

// Throws drift::Error naming the file, line, key, value and the valid range.
// A non-empty `terrain` replaces the [terrain] dem the file names.
soil::SoilScenario read_soil_scenario(const std::filesystem::path& path,
                                      const std::filesystem::path& terrain = {});

// The DEM the scenario's [terrain] names (resolved as read_soil_scenario does),
// or none: an input of the run, which OutputSet refuses as an output, so that
// `drift soil s.toml --surface dem.tif` cannot replace the dem.tif it reads.
std::filesystem::path soil_scenario_dem(const std::filesystem::path& path);

}  // namespace drift::pipeline
