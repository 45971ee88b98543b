// Reading a raster a window at a time while the dataset stays open: the
// out-of-core renderer's source of heights (render/paged_terrain.h), which
// asks for one page of a VRT or tiled GeoTIFF of any size at a time instead of
// the whole raster (terrain/raster_io.h reads everything at once).
//
// GDAL stays private to terrain: the dataset lives behind this class. It is
// not thread-safe (a GDALDataset is not): callers serialise their reads.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "terrain/grid.h"

namespace drift::terrain {

class RasterBlockReader {
 public:
  // Opens band 1 of `path`, and holds GDAL's own block cache to 64 MiB (for
  // the whole process: the reader's caller caches what it reads). Throws drift::Error naming the
  // file for a missing or unreadable raster or an unusable georeference.
  explicit RasterBlockReader(const std::filesystem::path& path);
  ~RasterBlockReader();
  RasterBlockReader(const RasterBlockReader&) = delete;
  RasterBlockReader& operator=(const RasterBlockReader&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  const GeoReference& geo() const { return geo_; }
  const std::filesystem::path& path() const { return path_; }

  // Cells [x, x + w) x [y, y + h), row-major, nodata as NaN (as read_raster
  // gives them). Throws drift::Error on a read failure or an infinite or
  // absurd height (|z| > 1e7 m, as read_raster refuses).
  std::vector<float> read(int x, int y, int w, int h) const;

  // The whole raster resampled to at most `max_side` cells a side (nearest
  // cell; GDAL reads its overviews for it when it has them), with the
  // georeference of the coarser grid. Cheap stand-in for what needs the
  // relief only roughly (placing a camera over the ground).
  HeightField read_coarse(int max_side) const;

 private:
  struct Dataset;
  std::unique_ptr<Dataset> ds_;
  std::filesystem::path path_;
  int width_ = 0, height_ = 0;
  GeoReference geo_;
};

}  // namespace drift::terrain
