// Reading any raster GDAL reads into a Grid<float>, and writing float32
// compressed GeoTIFFs that keep the georeference.
//
// In memory, invalid cells are NaN whatever nodata value the file declared;
// GeoReference::nodata keeps the declared value for information.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "terrain/grid.h"

class GDALDataset;  // GDAL stays private to terrain: only its own sources hold one

namespace drift::terrain {

// Registers GDAL's drivers once and routes GDAL's messages into our errors
// instead of stderr. Safe to call many times from any thread.
void ensure_gdal();

// The last message GDAL reported on this thread (empty if none).
std::string last_gdal_message();

struct RasterWindow {
  int x_off = 0, y_off = 0, width = 0, height = 0;  // pixels of the source
};

struct ReadOptions {
  int band = 1;                        // 1-based, as in GDAL
  std::optional<RasterWindow> window;  // read a part only (crop at read time)
  // Heights (and quantities like them) are refused beyond |1e7| or infinite,
  // in a message about heights; false for a raster of other values (material
  // indices), which its caller checks and names itself.
  bool heights = true;
};

// Header facts, read without loading the cells.
struct RasterHeader {
  int width = 0, height = 0, bands = 0;
  std::string driver;  // GDAL short name, e.g. "GTiff", "SRTMHGT"
  std::string data_type;
  GeoReference geo;
};

RasterHeader read_raster_header(const std::filesystem::path& path);

// GDAL reads a pixel-interleaved file a block at a time across all its bands,
// however few it is asked for: an 11012-cell row of some 63,000 Int16 bands is
// 1.4 GB read for one row of band 1 (found by fuzz_raster). Throws unless a
// row of `width` cells across `bands` bands of `bytes_per_cell` fits, the
// least such a block holds.
void require_row_across_bands_memory(std::uint64_t width, int bands, int bytes_per_cell,
                                     const std::filesystem::path& path);

// Throws drift::Error naming the file for: a missing file, a file GDAL cannot
// read as a raster, a band that does not exist, a read failure (truncated or
// corrupt data), or a raster larger than the memory available.
HeightField read_raster(const std::filesystem::path& path, const ReadOptions& options = {});

// For terrain's own sources that hold a GDAL dataset already (the warped grid
// of an import, kept in memory): read it as read_raster reads a file. `name`
// is what errors call the data (the file it came from).
HeightField read_dataset(GDALDataset& dataset, const std::filesystem::path& name,
                         const ReadOptions& options = {});

struct WriteOptions {
  std::string description;  // stored as the band description (e.g. "snow depth (m)")
  std::string units;        // band unit type, e.g. "m"
};

// Float32 GeoTIFF, DEFLATE with the floating-point predictor, tiled when large,
// georeference and CRS kept, NaN declared as nodata. Written atomically.
void write_geotiff(const HeightField& grid, const std::filesystem::path& path,
                   const WriteOptions& options = {});

}  // namespace drift::terrain
