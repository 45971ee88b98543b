// The snow-cover descriptor of paper 001 (Nakatani, Fujishiro and Ohno, "Design
// of Surface Descriptor for Rendering Snow-Covered Terrain", after Miller 1994's
// Tangent Sphere Accessibility), with the decisions docs/snow.md records: per
// grid point a value t in [0, 1], 0 = snow, 1 = bare rock.
//
//   1. smooth the DEM k times over the diamond of region n;
//   2. TSA of the smoothed surface at each point (paper eq. 3);
//   3. transfer g(TSA) with probe radius r and floor b (paper eq. 4);
//   4. altitude: snow = (1 - g) a(z), a = (z / z_max)^2 or a snow line;
//   5. smooth t once;
//   6. sun (paper 3.4.2, lines 10-15): each triangle around the point that faces
//      within theta1 of the sun's side updates t = t phi + (1 - phi), phi its
//      normalised angle, one triangle after the other.
//
// Lengths are metric by default (docs/snow.md, Steps 1 and 3, and "Metric
// defaults on finer DEMs"): the probe radius in metres and the smoothing region
// in units of the paper's 50 m grid spacing, widened to as many cells as that is
// on a finer DEM, so that a DEM and the same ground sampled finer give the same
// descriptor. Cells can be asked for explicitly.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>

#include "snow/cover_options.h"
#include "terrain/grid.h"
#include "terrain/progress.h"

namespace drift::snow {

// The paper's grid spacing (its Hodaka DEM, 50 m mesh, section 5): the unit of its
// smoothing region and, at 0.1 per cell, of its probe radius.
constexpr double kPaperCellM = 50.0;

// Neighbours within L1 distance n of a point, itself excluded: the paper's
// 4n + 2n(n - 1) (fig. 8).
int smoothing_neighbour_count(int region);

// One smoothing pass: new height = (own + mean of the region-n diamond) / 2.
// Beyond the border the nearest edge cell stands in. NaN must not occur.
// The diamond sums are exact (heights as integers of 2^-32 m, 128-bit sums)
// and cost O(1) a cell whatever n: each diamond is its west neighbour's plus
// and minus two edges, each edge two runs of diagonal prefix sums.
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

// The region n in cells and the probe radius in metres that `o` gives on a DEM
// with cells of `cell_m` metres.
int region_in_cells(const CoverOptions& o, double cell_m);
double radius_in_metres(const CoverOptions& o, double cell_m);

struct CoverResult {
  terrain::HeightField descriptor;     // t in [0, 1], the DEM's georeference
  terrain::HeightField accessibility;  // TSA in metres (+inf: unbounded)
  bool southern = false;               // the hemisphere used for the sun
};

// The whole descriptor. Throws drift::Error for nodata cells, a non-metric or
// rotated DEM, or options out of range.
CoverResult snow_cover(const terrain::HeightField& dem, const CoverOptions& options,
                       const ProgressFn& progress = no_progress);

// The halo a block needs so that its cells get the whole DEM's bits: k n
// (k smoothing passes over the region n, in cells) + 3 (the normals' 3 x 3, the
// TSA's neighbour normals, the smoothing of t).
int cover_halo(const CoverOptions& o, double cell_m);

// The descriptor block by block, for DEMs larger than memory: a first pass
// reads the DEM a block at a time for its highest cell (the altitude factor's
// z_max) and its nodata; the second reads each block with cover_halo cells
// around it, runs steps 1-6 on that window and writes the block of each
// output (tiled float32 GeoTIFFs, terrain/raster_blocks.h; through the open
// OutputSet if any). The outputs hold the bits snow_cover gives on the whole
// DEM, whatever the block size and thread count
// (tests/snow/snow_cover_tiled_test.cpp). Memory: a window of
// (block + 2 halo)^2 cells at 24 bytes, the smoothing's prefix sums and
// GDAL's cache, checked (DRIFT_MEMORY_LIMIT) before any work.
constexpr int kCoverBlock = 2048;
// The default block for a halo of `halo` cells (issue 36): a block of 2048
// beside the 753-cell halo of the metric defaults on a 1 m DEM was a window
// of 3554^2 cells of which the block was a third. At least 4 halos a side
// (the block then at least 4/9 of its window), a multiple of 256 (the
// output's tiles), never below kCoverBlock; shrunk (not below kCoverBlock)
// while its window, at kCoverBytesPerCell, would need more than half of
// `available` bytes.
int default_cover_block(int halo, std::uint64_t available);
struct CoverFiles {
  std::filesystem::path dem;            // the DEM (any raster GDAL reads, in metres)
  std::filesystem::path cover;          // 1 - t (empty: not written)
  std::filesystem::path descriptor;     // t (empty: not written)
  std::filesystem::path accessibility;  // TSA in metres (empty: not written)
  int block = 0;  // cells a side; 0: DRIFT_BLOCK_CELLS if set, else default_cover_block
};
struct CoverFilesResult {
  int width = 0, height = 0, block = 0, halo = 0;
  double cell_m = 0.0;  // the DEM's cell size
  bool southern = false;
  double mean_cover = 0.0;  // mean of 1 - t over the DEM
};
CoverFilesResult snow_cover_to_files(const CoverFiles& files, const CoverOptions& options,
                                     const ProgressFn& progress = no_progress);

}  // namespace drift::snow
