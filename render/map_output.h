// A map render's files (docs/rendering.md, "Maps"): the frame lies on the DEM
// in a GIS to the pixel because it carries the DEM's CRS and a geotransform
// of the map's box and cell. A GeoTIFF holds both itself (8-bit sRGB R, G, B,
// as the PNG); a PNG gets a world file (.pgw: the six numbers of the
// geotransform, the first pixel's centre) and GDAL's .png.aux.xml with the
// CRS, which QGIS and GDAL read beside it.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "render/image.h"
#include "render/tonemap.h"

namespace drift::render {

struct MapGeoreference {
  // GDAL's: x = gt[0] + col gt[1], y = gt[3] + row gt[5] at pixel corners.
  std::array<double, 6> geotransform{0, 1, 0, 0, 0, -1};
  std::string crs_wkt;  // empty: no CRS (an unreferenced grid)
};

// True for .tif and .tiff (case-insensitive).
bool is_geotiff_path(const std::filesystem::path& path);

// The files besides a map PNG: NAME.pgw and NAME.png.aux.xml.
std::vector<std::filesystem::path> map_png_sidecars(const std::filesystem::path& png);

// Writes the frame's R, G, B as the PNG would show them into a GeoTIFF with
// the georeference; atomically.
void write_map_geotiff(const Image& linear, const DisplayTransform& display,
                       const MapGeoreference& geo, const std::filesystem::path& path);

// Writes the world file and .aux.xml of map_png_sidecars(png); atomically.
void write_map_png_sidecars(const std::filesystem::path& png, const MapGeoreference& geo);

}  // namespace drift::render
