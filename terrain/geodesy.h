// Where a raster is on the globe: conversions between its CRS and WGS 84
// longitude/latitude (degrees), by GDAL/PROJ.
#pragma once

#include <array>
#include <string>

#include "terrain/grid.h"

namespace drift::terrain {

// lon/lat (WGS 84, degrees) of point (x, y) in the CRS given as WKT. Throws
// drift::Error if the CRS is empty or PROJ cannot transform the point.
std::array<double, 2> to_lonlat(const std::string& crs_wkt, double x, double y);

// (x, y) in the CRS given as WKT of lon/lat (WGS 84, degrees); throws likewise.
std::array<double, 2> from_lonlat(const std::string& crs_wkt, double lon, double lat);

// True if the CRS given as WKT is geographic (degrees); false for projected
// CRSs and for an empty WKT (a local grid in metres).
bool is_geographic(const std::string& crs_wkt);

// lon/lat of the centre of a raster with this georeference and size.
std::array<double, 2> centre_lonlat(const GeoReference& geo, int width, int height);

// Meridian convergence at the centre of a raster with this georeference and
// size: the angle from the grid's north (+y) to true north, in degrees,
// clockwise (east of grid north is positive). A true azimuth plus this is the
// grid azimuth. Throws as to_lonlat does for a raster without a CRS.
double grid_convergence_deg(const GeoReference& geo, int width, int height);

}  // namespace drift::terrain
