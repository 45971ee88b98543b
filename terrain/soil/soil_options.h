// The soil simulation's options. Their ranges, flags and keys live in one
// table, terrain/soil/soil_parameters.h.
#pragma once

#include "terrain/soil/advection.h"
#include "terrain/soil/soil_type.h"

namespace drift::soil {

struct SoilOptions {
  double dt = 1.0 / 60.0;
  double gravity = 9.81;
  int propagation_iterations = 4;
  OverflowHeuristic overflow = OverflowHeuristic::Up;
  int overflow_passes = 4;
  bool settle = true;
  bool slippage = true;
  SoilType soil;

  // Throws terrain::ParameterError naming the field, its value and the range
  // (terrain/soil/soil_parameters.toml).
  void validate() const;
};

}  // namespace drift::soil
