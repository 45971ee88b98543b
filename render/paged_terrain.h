// The out-of-core terrain (issue 36 item 2): a DEM of any size (a GDAL VRT or
// tiled GeoTIFF) traced at full resolution from pages of heights read on
// demand through an LRU cache under a memory budget (render/block_cache.h),
// instead of the whole raster in memory (TerrainScene's HeightGrid).
//
// Opening scans the raster once, strips of page_cells() rows read side by
// side on every thread (a GDAL dataset each), for what the scene needs up
// front: the lowest valid height (the local frame's origin and
// the nodata fill, as terrain/local_frame.h gives them in core), the highest
// and lowest vertices, and the min-max leaves of the height field's tree
// (render/height_field.h: 8 B per 4 x 4 cells, 0.67 B a cell with the levels
// above). Those stay in memory; the heights themselves live in the pages.
//
// Each page is page_cells() cells a side with its (page_cells() + 1)^2
// vertices, converted exactly as TerrainScene converts a DEM in core
// (nodata -> the lowest valid height, then h k - z0 in float), so whatever
// the cache holds or drops the heights a ray meets are the same bits.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "render/block_cache.h"
#include "render/height_field.h"
#include "terrain/grid.h"

namespace drift::terrain {
class RasterBlockReader;
}

namespace drift::render {

class PagedTerrain final : public HeightSource {
 public:
  static constexpr int kDefaultPageCells = 256;  // one GDAL block of a 256-tiled GeoTIFF

  // Opens and scans `dem` (band 1). Throws drift::Error naming the file for an
  // unreadable raster, a rotated or non-positive cell size, a raster under
  // 2 x 2 cells or all nodata, and for a budget below one page.
  PagedTerrain(const std::filesystem::path& dem, std::uint64_t memory_budget,
               float vertical_exaggeration, int page_cells = kDefaultPageCells);
  ~PagedTerrain() override;

  int page_cells() const override { return page_cells_; }
  HeightPage page(int page_x, int page_y, std::shared_ptr<const void>& pin) const override;
  // One vertex's height (local frame), through the cache.
  float at(int c, int r) const;

  // The frame of the heights (HeightGrid::z stays empty), its CRS origin,
  // the raster's georeference.
  const HeightGrid& frame() const { return frame_; }
  Eigen::Vector3d origin() const { return origin_; }
  const terrain::GeoReference& geo() const;
  float exaggeration() const { return exaggeration_; }
  // Embree's primitives out of core: groups of kGroup x kGroup blocks (a
  // BVH over 16 times fewer boxes), and what its BVH is counted at in the
  // budget a group (Embree 3's BVH4 over user geometry: about 3 nodes of
  // 4 boxes and a primitive reference a group, rounded up).
  static constexpr int kGroup = 4;
  static constexpr std::uint64_t kBvhBytesAGroup = 256;
  // The blocks' min-max of the scan (HeightFieldBlocks::kBlock cells each)
  // and the coarse samples, moved out once, to HeightFieldBlocks.
  std::vector<HeightFieldBlocks::MinMax> take_block_bounds() { return std::move(leaves_); }
  std::vector<float> take_coarse() { return std::move(coarse_); }
  // Bytes held outside the pages and counted in the budget: block bounds,
  // coarse samples and the BVH's allowance.
  std::uint64_t held_bytes() const { return held_bytes_; }
  // Highest and lowest vertex (local), the first in row-major order on a tie.
  Eigen::Vector3f highest() const { return highest_; }
  Eigen::Vector3f lowest() const { return lowest_; }

  BlockCacheStats cache_stats() const { return cache_->stats(); }
  std::uint64_t scan_bytes() const { return scan_bytes_; }
  std::uint64_t budget() const { return cache_->budget(); }
  std::uint64_t page_bytes() const;

 private:
  void scan();
  std::vector<float> load(std::uint64_t key) const;

  // The raster's reader on this thread (one GDAL dataset a thread: a dataset
  // is not thread-safe, so pages missed on two threads are read side by side).
  terrain::RasterBlockReader& reader() const;

  std::unique_ptr<terrain::RasterBlockReader> reader_;
  struct Readers;
  std::unique_ptr<Readers> readers_;
  std::unique_ptr<BlockCache> cache_;
  int page_cells_;
  int pages_x_ = 0, pages_y_ = 0;
  float exaggeration_ = 1.0f;
  float fill_ = 0.0f;  // the lowest valid height: nodata's stand-in
  float z0_ = 0.0f;    // local z = h k - z0
  HeightGrid frame_;
  Eigen::Vector3d origin_{0, 0, 0};
  std::vector<HeightFieldBlocks::MinMax> leaves_;  // the blocks' min-max
  std::vector<float> coarse_;
  std::uint64_t held_bytes_ = 0;
  Eigen::Vector3f highest_{0, 0, 0}, lowest_{0, 0, 0};
  std::uint64_t scan_bytes_ = 0;
};

}  // namespace drift::render
