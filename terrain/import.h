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

namespace drift::terrain {

struct ImportOptions {
  std::optional<std::array<double, 4>> crop;         // xmin, ymin, xmax, ymax in the DEM's CRS
  std::optional<std::array<double, 4>> crop_lonlat;  // west, south, east, north in degrees (WGS 84)
  std::optional<double> resample_m;  // output cell size in metres (> 0); default: the source's
  bool keep_crs = false;             // do not reproject a geographic DEM
  double exaggeration = 1.0;         // multiply heights, (0, 100]

  // Throws ParameterError (terrain/parameter.h) naming the field out of range.
  void validate() const;
};

struct ImportResult {
  HeightField grid;
  std::vector<std::string> report;  // one line per thing done, for the user
  std::size_t filled_cells = 0;
};

ImportResult import_dem(const std::filesystem::path& path, const ImportOptions& options);

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
