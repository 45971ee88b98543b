// Ground beyond the DEM's edge, so that no view ends in a cut: a ring of
// Embree grids around the DEM (a strip along each edge at the DEM's own
// vertex spacing along it, growing geometrically outward, and four corner
// grids) whose inner row is the DEM's edge row, so the seam is watertight
// and continuous. It is real geometry: rays hit it, it casts shadows, the
// depth and sky-mask AOVs report it as ground, the material rules shade it.
//
// Its heights, at a point a distance d outside the DEM (nearest edge point
// p), in order of preference:
// 1. a surround raster (a coarser DEM in the same CRS; of several, the finest
//    that covers the point wins), shifted by the seam's mismatch (the DEM's
//    edge height less the raster's at the nearest edge point), the shift
//    fading out over `blend` m: a raster the DEM was cut from goes on as
//    itself, a coarser one meets the edge without a step;
// 2. else the fallback: the DEM's edge continued outward and flattened, the
//    edge heights around p averaged over a window that widens with d (d/2 on
//    each side), relaxing to the DEM's mean height over a length of a quarter
//    of the DEM's size, plus smooth ridges (value-noise octaves of 12 km down
//    to 300 m, never finer than the grid resolves there) whose amplitude,
//    the DEM's height deviation, grows from 0 at the edge over that length:
//    a range that goes on in the DEM's own relief and fades into the aerial
//    perspective, never a flat plane or a wall;
// and, for both, the Earth's curvature: the ground drops by d^2 / 2R
// (R = 6371 km, 280 m at 60 km), so the far range sinks towards the horizon.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "render/height_field.h"
#include "terrain/grid.h"

namespace drift::render {

struct SurroundOptions {
  double reach = 100000.0;  // metres beyond the DEM's edge; 0: no surround
  // Coarser DEMs around the DEM, in its CRS (metres), any order.
  std::vector<terrain::HeightField> rasters;
  double blend = 0.0;  // metres over which the edge blends into a raster; 0: 10 of its cells
};

// The DEM as the scene holds it: its local heights (row 0 north, x east;
// render/height_field.h) and the transform from local to CRS coordinates.
struct DemVertices {
  const HeightGrid* heights = nullptr;
  int width = 0, height = 0;
  float dx = 1.0f, dy = 1.0f;
  Eigen::Vector3d origin{0, 0, 0};  // local -> CRS shift (heights exaggerated)
  float exaggeration = 1.0f;
  // The DEM as 16-bit heights with no floats in memory (TerrainScene's
  // streamed 16-bit scene; heights->z is empty): the vertices read from
  // `quantised`, and the sums of the heights and their squares over every
  // vertex, added in row-major order as the floats would be (the ring's mean
  // and spread), given by the scene that saw each strip once.
  const QuantisedHeights* quantised = nullptr;
  double sum = 0.0, sum_squares = 0.0;
  float at(int c, int r) const { return quantised ? quantised->at(c, r) : heights->at(c, r); }
};

struct SurroundGrids {
  std::vector<Eigen::Vector3f> vertices;  // local coordinates
  // Smooth shading normals at the vertices (unit, facing up): central
  // differences over each block of vertices, so far ridges are shaded as
  // the slopes they stand for instead of flat facets.
  std::vector<Eigen::Vector3f> normals;
  struct Grid {
    unsigned start = 0, stride = 0;
    unsigned short width = 0, height = 0;
  };
  std::vector<Grid> grids;
  float reach = 0.0f;
};

// The surround's height (local z) at local (x, y); inside the DEM its own
// bilinear height. For tests and the grids below.
class SurroundHeight {
 public:
  SurroundHeight(const DemVertices& dem, const SurroundOptions& options);
  // `spacing`: the grid's resolution there (metres), which limits the ridges.
  float operator()(float x, float y, float spacing) const;
  // Distance of (x, y) outside the DEM's rectangle (0 inside).
  float outside_distance(float x, float y) const;

 private:
  float edge_mean(float x, float y, float half_width) const;
  float dem_height(float x, float y) const;
  // The finest surround raster covering local (x, y): its height (local z)
  // and cell size, or none.
  struct RasterSample {
    float z = 0.0f;
    double cell = 0.0;
  };
  std::optional<RasterSample> raster_height(float x, float y) const;
  // The continued edge: the fallback (no raster covers the edge).
  float continued_edge(float x, float y, float d, float spacing) const;

  DemVertices dem_;
  const SurroundOptions* options_;
  std::vector<double> sat_;  // summed-area table of the vertex heights
  float mean_ = 0.0f, deviation_ = 0.0f, decay_ = 1.0f;
  float x0_ = 0, y0_ = 0, x1_ = 0, y1_ = 0;  // the DEM's rectangle (local)
};

// The ring of grids, or nothing when options.reach is 0. Throws drift::Error
// when the memory check fails.
SurroundGrids build_surround(const DemVertices& dem, const SurroundOptions& options);

}  // namespace drift::render
