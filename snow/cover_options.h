// The snow-cover descriptor's options (paper 001). Their ranges, units and
// meanings live in one table, snow/cover_parameters.h.
#pragma once

#include <optional>

namespace drift::snow {

enum class Hemisphere { Auto, North, South };

// How the sun step combines the triangles around a point.
enum class SunStep {
  PerTriangle,  // the paper's rule: t = t phi + (1 - phi) for each facing triangle
  Mean,         // phi averaged over all 12 (1 for those not facing), applied once
};

// The ranges, units and meanings of the numeric fields are in
// snow/cover_parameters.toml's table (docs/snow.md's options table).
struct CoverOptions {
  double region = 3.0;          // smoothing region n in the paper's 50 m cells
  int region_cells = 0;         // > 0: region n in this DEM's cells instead
  int iterations = 5;           // smoothing passes k
  double radius_m = 2750.0;     // probe radius r in metres: the paper's 5.5 (55 x 50 m)
  double radius_cells = 0.0;    // > 0: probe radius in this DEM's cells instead
  double floor = 0.0;           // b: how much rock shows at TSA 0
  double sun_range_deg = 60.0;  // theta1; 0 turns the sun off
  SunStep sun_step = SunStep::PerTriangle;
  std::optional<double> snow_line_m;         // altitude factor: a snow line instead of (z/zmax)^2
  double band_m = 200.0;                     // ... with a transition band this wide
  Hemisphere hemisphere = Hemisphere::Auto;  // Auto: from the DEM's CRS (north if none)

  // Throws terrain::ParameterError naming the field out of its range.
  void validate() const;
};

}  // namespace drift::snow
