// The snow-cover descriptor of paper 001 (Ogawa, Dobashi, Nishita et al.,
// after Miller 1994's Tangent Sphere Accessibility), with the decisions of
// SPEC 3b: per grid point a value t in [0, 1], 0 = snow, 1 = bare rock.
//
//   1. smooth the DEM k times over the diamond of region n;
//   2. TSA of the smoothed surface at each point (paper eq. 3);
//   3. transfer g(TSA) with probe radius r and floor b (paper eq. 4);
//   4. altitude: snow = (1 - g) a(z), a = (z / z_max)^2 or a snow line;
//   5. smooth t once;
//   6. sun: faces within theta1 of the sun-facing direction lose snow.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "terrain/grid.h"
#include "terrain/progress.h"

namespace drift::snow {

// Neighbours within L1 distance n of a point, itself excluded: the paper's
// 4n + 2n(n - 1) (fig. 8).
int smoothing_neighbour_count(int region);

// One smoothing pass: new height = (own + mean of the region-n diamond) / 2.
// Beyond the border the nearest edge cell stands in. NaN must not occur.
terrain::HeightField smooth(const terrain::HeightField& dem, int region);

// Tangent Sphere Accessibility (metres) of every grid point, +infinity where
// no sphere is bounded (flat or convex ground). See tsa_at for the geometry.
terrain::HeightField tangent_sphere_accessibility(const terrain::HeightField& dem);

// TSA at (x, row): the radius of the largest sphere tangent to the surface at
// X (normal N) that no neighbouring tangent plane cuts. Paper eq. (3),
// t = ((X - P) . M) / (1 - N . M), taken for the 12 triangles around X of
// both diagonal splits (fig. 9) with P and M the point and normal of the
// surface at each triangle's far vertices: the triangles' own planes pass
// through X and would give 0. The smallest positive t wins.
float tsa_at(const terrain::HeightField& dem, const terrain::Grid<Eigen::Vector3f>& normals, int x,
             int row);

enum class Hemisphere { Auto, North, South };

struct CoverOptions {
  int region = 3;                     // smoothing region n, cells [1, 32]
  int iterations = 5;                 // smoothing passes k [0, 100]
  double radius_m = 0.0;              // probe radius r in metres; 0: radius_cells x cell size
  double radius_cells = 55.0;         // the paper's 5.5 at its 0.1 grid spacing
  double floor = 0.0;                 // b in [0, 1]: how much rock shows at TSA 0
  double sun_range_deg = 60.0;        // theta1 in [0, 90]; 0 turns the sun off
  std::optional<double> snow_line_m;  // altitude factor: a snow line instead of (z/zmax)^2
  double band_m = 200.0;              // ... with a transition band this wide
  Hemisphere hemisphere = Hemisphere::Auto;  // Auto: from the DEM's CRS (north if none)

  // Throws terrain::ParameterError naming the field out of its range.
  void validate() const;
};

struct CoverResult {
  terrain::HeightField descriptor;     // t in [0, 1], the DEM's georeference
  terrain::HeightField accessibility;  // TSA in metres (+inf: unbounded)
  bool southern = false;               // the hemisphere used for the sun
};

// The whole descriptor. Throws drift::Error for nodata cells, a non-metric or
// rotated DEM, or options out of range.
CoverResult snow_cover(const terrain::HeightField& dem, const CoverOptions& options,
                       const ProgressFn& progress = no_progress);

}  // namespace drift::snow
