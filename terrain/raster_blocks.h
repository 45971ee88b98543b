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

namespace drift {
class AtomicFile;
}

namespace drift::terrain {

struct WriteOptions;

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
  // heights = false: values that are not heights (material indices) are
  // returned as they are, nodata as NaN.
  std::vector<float> read(int x, int y, int w, int h, bool heights = true) const;

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

// Writing a float32 GeoTIFF a block at a time: the tiled stages' output
// (drift import, snow cover) on rasters larger than memory. Internally tiled
// 256 x 256, DEFLATE with the floating-point predictor, BigTIFF when large,
// NaN declared nodata, the georeference kept: what write_geotiff
// (terrain/raster_io.h) writes, cell for cell. Written through AtomicFile, so
// within an OutputSet the set's temporary file is written and nothing reaches
// the target before the set commits. GDAL's block cache (held to 64 MiB, as
// RasterBlockReader holds it) carries the dirty tiles to disk: memory stays
// bounded by the blocks in flight, not the raster. Not thread-safe.
class RasterBlockWriter {
 public:
  // Creates the file; throws drift::Error naming it if it cannot be.
  RasterBlockWriter(const std::filesystem::path& path, int width, int height,
                    const GeoReference& geo, const WriteOptions& options);
  ~RasterBlockWriter();  // an unfinished file is removed (AtomicFile)
  RasterBlockWriter(const RasterBlockWriter&) = delete;
  RasterBlockWriter& operator=(const RasterBlockWriter&) = delete;

  // Cells [x, x + w) x [y, y + h) from `cells` (row-major, w x h).
  void write(int x, int y, int w, int h, const float* cells);
  // Flushes and closes the file and commits it (to the open OutputSet's
  // temporary file if there is one); throws drift::Error on a failed write.
  void finish();

 private:
  struct Dataset;
  // Declared before the dataset: the dataset closes before an unfinished
  // file is removed.
  std::unique_ptr<AtomicFile> file_;
  std::filesystem::path path_;
  std::unique_ptr<Dataset> ds_;
  int width_ = 0, height_ = 0;
};

// The cell count a side of the blocks the tiled stages work in: `requested`
// if > 0, else DRIFT_BLOCK_CELLS if set (tests force small blocks through it),
// else `fallback`. Throws drift::Error naming DRIFT_BLOCK_CELLS if it is not a
// whole number in [16, 1048576].
int block_cells(int requested, int fallback);

}  // namespace drift::terrain
