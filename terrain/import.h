// DEM import: any raster GDAL reads -> a north-up float32 height field in
// metres. Geographic (degree) DEMs are warped with GDAL's warp API to the UTM
// zone of their centre, so that every slope computed later is right; nodata is
// filled; optional crop, resampling and vertical exaggeration.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "terrain/grid.h"
#include "terrain/progress.h"

namespace drift::terrain {

struct ImportOptions {
  std::optional<std::array<double, 4>> crop;         // xmin, ymin, xmax, ymax in the DEM's CRS
  std::optional<std::array<double, 4>> crop_lonlat;  // west, south, east, north in degrees (WGS 84)
  std::optional<double> resample_m;  // output cell size in metres (> 0); default: the source's
  bool keep_crs = false;             // do not reproject a geographic DEM
  double exaggeration = 1.0;         // multiply heights, (0, 100]
  // import_dem_to_file's blocks, cells a side: 0 takes DRIFT_BLOCK_CELLS if
  // set, else kImportBlock; [16, 1048576] otherwise.
  int block = 0;

  // Throws ParameterError (terrain/parameter.h) naming the field out of range.
  void validate() const;
};

struct ImportResult {
  HeightField grid;
  std::vector<std::string> report;  // one line per thing done, for the user
  std::size_t filled_cells = 0;
};

// In one pass: the whole grid in memory (three times over at the nodata fill).
ImportResult import_dem(const std::filesystem::path& path, const ImportOptions& options);

// Block by block, for rasters larger than memory: the source is warped as a
// virtual dataset (GDAL warps the blocks read), and each block is read with a
// halo, its nodata filled, exaggerated and written to `output`, a tiled
// float32 GeoTIFF (terrain/raster_blocks.h; through the open OutputSet if
// any). The halo is what the fill needs: a cell r cells from the nearest valid
// one depends on the cells within r of it, so the halo starts at 8 cells and
// grows fourfold until it reaches r + 1 beyond every filled cell of the block.
// Heights need no other neighbourhood. The file holds the bits import_dem
// gives, whatever the block size (tests/terrain/import_tiled_test.cpp).
// Memory: a window of (block + 2 halo)^2 cells at 28 bytes and GDAL's caches
// (128 MiB), checked (DRIFT_MEMORY_LIMIT) before each window is read.
constexpr int kImportBlock = 2048;
struct ImportFileResult {
  int width = 0, height = 0;  // the grid written
  int block = 0;              // the block side used
  int max_fill_halo = 0;      // the widest fill halo a block needed
  std::vector<std::string> report;
  std::size_t filled_cells = 0;
};
ImportFileResult import_dem_to_file(const std::filesystem::path& path,
                                    const std::filesystem::path& output,
                                    const ImportOptions& options,
                                    const ProgressFn& progress = no_progress);

// Cell size in metres (east-west, north-south) of a raster with this
// georeference: as is for projected CRSs, from the WGS 84 ellipsoid at the centre
// latitude for geographic ones. `crs_name` receives the CRS's name if known.
std::array<double, 2> cell_size_metres(const GeoReference& geo, int width, int height,
                                       std::string* crs_name = nullptr);

// UTM EPSG code (326zz north, 327zz south) of the zone holding lon/lat.
int utm_epsg(double lon_deg, double lat_deg);

// Fills NaN cells with the mean of their valid 8-neighbours, growing inwards
// ring by ring (deterministic). Returns the number filled; throws drift::Error
// if the grid holds no valid cell.
std::size_t fill_nodata(HeightField& grid, const std::string& what);

}  // namespace drift::terrain
