// Snowfall's options (paper 003). Their ranges, units and meanings live in one
// table, snow/snowfall_parameters.h.
#pragma once

#include <cstdint>

#include "snow/adhesion_coverage.h"
#include "snow/snowfall_probability.h"

namespace drift::snow {

struct SnowfallOptions {
  double azimuth_deg = 0.0;
  double elevation_deg = 90.0;
  double spread_deg = 5.0;
  int maps = 16;
  double rate_m_per_h = 0.02;
  double hours = 10.0;
  double repose_deg = 40.0;
  std::uint64_t seed = 1;
  double mesh_max_edge = 0.25;
  ProbabilityOptions occlusion;
  CoverageOptions coverage;
  double tolerance = 1e-6;  // m: object stabilisation stops when nothing moves more per pass
  // m: on the ground a pair steeper than repose by less than this, or a film
  // thinner, is stable (stabilise_grid.h)
  double ground_tolerance = 1e-3;
  int max_iterations = 100000;
  // The coarse-to-fine start of the ground's stabilisation (stabilise_grid.h
  // StabiliseOptions::coarse_levels); 0: the passes on the grid alone.
  int coarse_levels = 0;
  // The ground settled in one step (StabiliseOptions::direct) instead of by
  // the passes: `--stabilise direct`.
  bool direct_stabilise = false;
  // With direct_stabilise: the snow settled in this many equal layers
  // (StabiliseOptions::direct_layers): `--direct-layers`.
  int direct_layers = 4;
  // > 0: the ground's occlusion swept on blocks of this many cells a side,
  // each with its halo (snow/occlusion_blocks.h; the same bits as one pass);
  // ground alone, by the sweep. 0: one pass.
  int block = 0;

  // Throws drift::Error naming the parameter, its value and the valid range.
  void validate() const;
};

}  // namespace drift::snow
