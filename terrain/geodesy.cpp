#include "terrain/geodesy.h"

#include <ogr_spatialref.h>

#include <cmath>
#include <memory>

#include "terrain/angles.h"
#include "terrain/error.h"

namespace drift::terrain {

namespace {

// Transforms one point from `from` to `to` (traditional x = lon/east order).
std::array<double, 2> transform(const std::string& from_wkt, bool from_wgs84, double x, double y) {
  if (!from_wgs84 && from_wkt.empty())
    throw Error(
        "the raster has no CRS, so it cannot be placed on the globe; "
        "give it one (gdal_edit.py -a_srs) or use CRS coordinates");
  OGRSpatialReference crs, wgs84;
  wgs84.importFromEPSG(4326);
  if (crs.importFromWkt(from_wkt.c_str()) != OGRERR_NONE)
    throw Error("the raster's CRS cannot be read by GDAL: " + from_wkt.substr(0, 80));
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  crs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> ct(
      from_wgs84 ? OGRCreateCoordinateTransformation(&wgs84, &crs)
                 : OGRCreateCoordinateTransformation(&crs, &wgs84));
  if (!ct || !ct->Transform(1, &x, &y))
    throw Error("cannot transform point (" + std::to_string(x) + ", " + std::to_string(y) +
                ") between the raster's CRS and longitude/latitude");
  return {x, y};
}

}  // namespace

std::array<double, 2> to_lonlat(const std::string& crs_wkt, double x, double y) {
  return transform(crs_wkt, false, x, y);
}

std::array<double, 2> from_lonlat(const std::string& crs_wkt, double lon, double lat) {
  if (crs_wkt.empty()) return transform(crs_wkt, false, lon, lat);  // the same error
  return transform(crs_wkt, true, lon, lat);
}

bool is_geographic(const std::string& crs_wkt) {
  if (crs_wkt.empty()) return false;
  OGRSpatialReference crs;
  return crs.importFromWkt(crs_wkt.c_str()) == OGRERR_NONE && crs.IsGeographic();
}

std::array<double, 2> centre_lonlat(const GeoReference& geo, int width, int height) {
  const auto c = geo.cell_center((width - 1) / 2.0, (height - 1) / 2.0);
  return to_lonlat(geo.crs_wkt, c[0], c[1]);
}

double grid_convergence_deg(const GeoReference& geo, int width, int height) {
  const auto lonlat = centre_lonlat(geo, width, height);
  // The grid direction of a step of 1e-3 degrees north from the centre.
  const auto centre = geo.cell_center((width - 1) / 2.0, (height - 1) / 2.0);
  const auto north = from_lonlat(geo.crs_wkt, lonlat[0], lonlat[1] + 1e-3);
  return degrees(std::atan2(north[0] - centre[0], north[1] - centre[1]));
}

}  // namespace drift::terrain
