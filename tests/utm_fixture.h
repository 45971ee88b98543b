// UTM test DEMs for the tests that check georeference (maps, EXR layers,
// meshes): the CRS as WKT, and a DEM from a formula written as a GeoTIFF.
#pragma once

#include <cpl_conv.h>
#include <ogr_spatialref.h>

#include <filesystem>
#include <string>

#include "terrain/raster_io.h"

namespace drift::testing {

// The CRS of an EPSG code as WKT.
inline std::string wkt_of_epsg(int epsg) {
  OGRSpatialReference srs;
  srs.importFromEPSG(epsg);
  char* wkt = nullptr;
  srs.exportToWkt(&wkt);
  std::string out = wkt;
  CPLFree(wkt);
  return out;
}

// WGS 84 / UTM zone 53N (Yarigatake's), EPSG:32653, as WKT.
inline std::string utm53_wkt() { return wkt_of_epsg(32653); }

// A width x height DEM of `cell` metres, north up, its north-west corner at
// (west, north) in `crs_wkt` (empty: none), z = f(col, row), written as
// dir/dem.tif.
template <class F>
std::filesystem::path write_dem(const std::filesystem::path& dir, int width, int height,
                                double west, double north, double cell, const std::string& crs_wkt,
                                F f) {
  terrain::GeoReference geo;
  geo.geotransform = {west, cell, 0.0, north, 0.0, -cell};
  geo.crs_wkt = crs_wkt;
  terrain::HeightField dem(width, height, 0.0f, geo);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) dem(c, r) = static_cast<float>(f(c, r));
  const std::filesystem::path path = dir / "dem.tif";
  terrain::write_geotiff(dem, path);
  return path;
}

}  // namespace drift::testing
