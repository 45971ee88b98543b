#include "render/paged_terrain.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/raster_blocks.h"

namespace drift::render {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// The scan's nodes: the height field's blocks (the tree below them comes
// with each page, HeightFieldBlocks::page_tree).
constexpr int kLeaf = HeightFieldBlocks::kBlock;
constexpr int kCoarse = HeightFieldBlocks::kCoarse;

}  // namespace

struct PagedTerrain::Readers {
  tbb::enumerable_thread_specific<std::unique_ptr<terrain::RasterBlockReader>> local;
};

terrain::RasterBlockReader& PagedTerrain::reader() const {
  std::unique_ptr<terrain::RasterBlockReader>& r = readers_->local.local();
  if (!r) r = std::make_unique<terrain::RasterBlockReader>(reader_->path());
  return *r;
}

PagedTerrain::PagedTerrain(const std::filesystem::path& dem, std::uint64_t memory_budget,
                           float vertical_exaggeration, int page_cells)
    : reader_(std::make_unique<terrain::RasterBlockReader>(dem)),
      readers_(std::make_unique<Readers>()),
      page_cells_(page_cells),
      exaggeration_(vertical_exaggeration) {
  const int w = reader_->width(), h = reader_->height();
  const std::string name = "the terrain raster '" + dem.string() + "'";
  if (w < 2 || h < 2) {
    throw Error(name + " must be at least 2 x 2 cells, got " + std::to_string(w) + " x " +
                std::to_string(h));
  }
  const terrain::GeoReference& geo = reader_->geo();
  if (!geo.north_up()) throw Error(name + " is rotated; warp it north-up first (drift import)");
  if (!(geo.cell_size_x() > 0) || !(geo.cell_size_y() > 0))
    throw Error(name + "'s cell size must be positive (north-up, metres)");
  // Every block of the height field must lie in one page.
  if (page_cells_ < HeightFieldBlocks::kBlock || page_cells_ % HeightFieldBlocks::kBlock != 0)
    throw Error("page size " + std::to_string(page_cells_) + " is not a multiple of " +
                std::to_string(HeightFieldBlocks::kBlock) + " cells");
  pages_x_ = (w - 2) / page_cells_ + 1;
  pages_y_ = (h - 2) / page_cells_ + 1;
  // What stays in memory counts against the budget too (issue 36): the
  // blocks' min-max, the coarse samples and Embree's BVH over the groups of
  // blocks; the pages get the rest.
  const std::uint64_t blocks =
      static_cast<std::uint64_t>((w - 2) / kLeaf + 1) * ((h - 2) / kLeaf + 1);
  const std::uint64_t groups =
      static_cast<std::uint64_t>((w - 2) / (kLeaf * kGroup) + 1) * ((h - 2) / (kLeaf * kGroup) + 1);
  held_bytes_ = blocks * sizeof(HeightFieldBlocks::MinMax) +
                static_cast<std::uint64_t>(HeightFieldBlocks::coarse_count(w)) *
                    HeightFieldBlocks::coarse_count(h) * sizeof(float) +
                groups * kBvhBytesAGroup;
  if (memory_budget < held_bytes_ + page_bytes())
    throw Error(name + ": a memory budget of " + std::to_string(memory_budget) +
                " B cannot hold one block of " + std::to_string(page_bytes()) +
                " B beside the bounds, coarse levels and BVH held in memory (" +
                std::to_string(held_bytes_) + " B); give at least " +
                std::to_string(held_bytes_ + page_bytes()) + " B");
  try {
    cache_ = std::make_unique<BlockCache>(memory_budget - held_bytes_, page_bytes(),
                                          [this](std::uint64_t key) { return load(key); });
  } catch (const Error& e) {
    throw Error(name + ": " + e.what());  // which render's budget, for which DEM
  }
  frame_.width = w;
  frame_.height = h;
  frame_.dx = static_cast<float>(geo.cell_size_x());
  frame_.dy = static_cast<float>(geo.cell_size_y());
  // What the DEM holds in memory, counted before the scan (it was not counted
  // at all: MemoryEstimate.RenderOutOfCoreAndMaps): what stays in memory
  // beside the pages (held_bytes_, above), GDAL's block cache (64 MiB at
  // most), and the larger of the scan's strips (a page of rows a thread,
  // freed after the scan) and the cache (its share of the budget, or every
  // page if they are fewer).
  const std::uint64_t cells = static_cast<std::uint64_t>(w - 1) * (h - 1), rows = page_cells_;
  const std::uint64_t pages = static_cast<std::uint64_t>(pages_x_) * pages_y_ * page_bytes();
  const std::uint64_t strips = rows * w * sizeof(float) *
                               static_cast<std::uint64_t>(tbb::this_task_arena::max_concurrency());
  require_memory(held_bytes_ +
                     std::min<std::uint64_t>(cells * sizeof(float), std::uint64_t{64} << 20) +
                     std::max(strips, std::min(memory_budget - held_bytes_, pages)),
                 name + " out of core (its blocks' bounds, GDAL's cache and the --memory-budget)",
                 "give a smaller --memory-budget, or resample the DEM");
  scan();
}

PagedTerrain::~PagedTerrain() = default;

const terrain::GeoReference& PagedTerrain::geo() const { return reader_->geo(); }

std::uint64_t PagedTerrain::page_bytes() const {
  const std::uint64_t side = static_cast<std::uint64_t>(page_cells_) + 1;
  return (side * side + HeightFieldBlocks::page_tree_floats(page_cells_)) * sizeof(float);
}

void PagedTerrain::scan() {
  const int w = frame_.width, h = frame_.height;
  const int cells_x = w - 1, cells_y = h - 1;
  const int leaves_x = (cells_x + kLeaf - 1) / kLeaf, leaves_y = (cells_y + kLeaf - 1) / kLeaf;
  leaves_.assign(static_cast<std::size_t>(leaves_x) * leaves_y, {kInf, -kInf});
  const int coarse_x = HeightFieldBlocks::coarse_count(w);
  coarse_.assign(static_cast<std::size_t>(coarse_x) * HeightFieldBlocks::coarse_count(h), 0.0f);
  // Strips of page_cells_ vertex rows [a, b), a a multiple of page_cells_, so
  // that a raster tiled in blocks of page_cells_ (or a divisor) decodes each
  // block once: a strip reaching one row into the next block row made GDAL
  // decode that block row twice, and at 65536 cells a side one block row
  // (64 MiB) no longer stayed in GDAL's 64 MiB cache. The strips are read side
  // by side, each thread through its own dataset (a GDALDataset is not
  // thread-safe; GDAL's block cache is). Leaf row iy spans vertex rows
  // [4 iy, 4 iy + 4]: the strip holding row 4 iy writes it; its last vertex
  // row may be the next strip's first, whose min-max per leaf column (the
  // strip's "head") is merged in afterwards. Min and max are exact, so the
  // leaves are the same bits whatever the strips or the threads.
  const int strip = page_cells_;
  const int strips = (h + strip - 1) / strip;
  struct StripResult {
    std::vector<HeightFieldBlocks::MinMax> head;  // row a's min-max per leaf column
    float lo = kInf, hi = -kInf;
    std::size_t lo_at = 0, hi_at = 0;
    std::uint64_t bytes = 0;
  };
  std::vector<StripResult> results(static_cast<std::size_t>(strips));
  tbb::parallel_for(0, strips, [&](int k) {
    const int a = k * strip, b = std::min(a + strip, h);
    const std::vector<float> rows = reader().read(0, a, w, b - a);
    const auto z = [&](int c, int r) { return rows[static_cast<std::size_t>(r - a) * w + c]; };
    StripResult& out = results[static_cast<std::size_t>(k)];
    out.bytes = rows.size() * sizeof(float);
    // Raw min-max (-inf as the lowest: it holds nodata, which becomes the
    // lowest valid height once that is known) of vertex rows [r0, r1] over
    // leaf column ix.
    const auto minmax = [&](int ix, int r0, int r1) {
      HeightFieldBlocks::MinMax m{kInf, -kInf};
      const int c0 = ix * kLeaf, c1 = std::min(c0 + kLeaf, cells_x);
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) {
          const float v = z(c, r);
          if (std::isnan(v)) {
            m.lo = -kInf;
          } else {
            m.lo = std::min(m.lo, v), m.hi = std::max(m.hi, v);
          }
        }
      return m;
    };
    for (int iy = a / kLeaf; iy < leaves_y && iy * kLeaf < b; ++iy) {
      const int r1 = std::min({iy * kLeaf + kLeaf, cells_y, b - 1});
      for (int ix = 0; ix < leaves_x; ++ix)
        leaves_[static_cast<std::size_t>(iy) * leaves_x + ix] = minmax(ix, iy * kLeaf, r1);
    }
    if (a > 0 && a % kLeaf == 0) {
      out.head.resize(static_cast<std::size_t>(leaves_x));
      for (int ix = 0; ix < leaves_x; ++ix)
        out.head[static_cast<std::size_t>(ix)] = minmax(ix, a, a);
    }
    // The coarse samples (every kCoarse-th vertex and the last), raw.
    for (int r = a; r < b; ++r) {
      if (r % kCoarse != 0 && r != h - 1) continue;
      const int j = r % kCoarse == 0 ? r / kCoarse : HeightFieldBlocks::coarse_count(h) - 1;
      for (int i = 0; i < coarse_x; ++i)
        coarse_[static_cast<std::size_t>(j) * coarse_x + i] =
            z(HeightFieldBlocks::coarse_vertex(i, w), r);
    }
    // The extremes, the first in row-major order on a tie.
    for (int r = a; r < b; ++r)
      for (int c = 0; c < w; ++c) {
        const float v = z(c, r);
        if (std::isnan(v)) continue;
        const std::size_t i = static_cast<std::size_t>(r) * w + c;
        if (v < out.lo) out.lo = v, out.lo_at = i;
        if (v > out.hi) out.hi = v, out.hi_at = i;
      }
  });
  float lo = kInf, hi = -kInf;
  std::size_t lo_at = 0, hi_at = 0;
  for (int k = 0; k < strips; ++k) {
    const StripResult& s = results[static_cast<std::size_t>(k)];
    scan_bytes_ += s.bytes;
    if (s.lo < lo) lo = s.lo, lo_at = s.lo_at;  // strictly: the earlier strip wins a tie
    if (s.hi > hi) hi = s.hi, hi_at = s.hi_at;
    if (s.head.empty()) continue;
    const int iy = k * strip / kLeaf - 1;  // the leaf row whose last vertex row is a
    for (int ix = 0; ix < leaves_x; ++ix) {
      HeightFieldBlocks::MinMax& m = leaves_[static_cast<std::size_t>(iy) * leaves_x + ix];
      const HeightFieldBlocks::MinMax& t = s.head[static_cast<std::size_t>(ix)];
      m.lo = std::min(m.lo, t.lo), m.hi = std::max(m.hi, t.hi);
    }
  }
  if (!std::isfinite(lo))
    throw Error("the terrain raster '" + reader_->path().string() +
                "' holds no valid height (all nodata)");
  // The local frame as terrain::local_frame gives it in core.
  const terrain::GeoReference& geo = reader_->geo();
  fill_ = lo;
  const auto centre = geo.cell_center((w - 1) / 2.0, (h - 1) / 2.0);
  origin_ = Eigen::Vector3d(centre[0], centre[1],
                            static_cast<double>(lo) * static_cast<double>(exaggeration_));
  const auto nw = geo.cell_center(0, 0);
  frame_.x0 = static_cast<float>(nw[0] - origin_.x());
  frame_.y0 = static_cast<float>(nw[1] - origin_.y());
  z0_ = static_cast<float>(origin_.z());
  // Leaves into the local frame: h k - z0 rounds monotonically, so the
  // extremes map to the extremes; a leaf with nodata reaches the fill.
  const float k = exaggeration_, z0 = z0_, filled = fill_ * k - z0;
  tbb::parallel_for(std::size_t{0}, leaves_.size(), [&](std::size_t i) {
    HeightFieldBlocks::MinMax& m = leaves_[i];
    const bool nodata = m.lo == -kInf;
    m.lo = nodata ? filled : m.lo * k - z0;
    m.hi = m.hi == -kInf ? filled : m.hi * k - z0;
    if (nodata) m.hi = std::max(m.hi, filled);
  });
  for (float& v : coarse_) v = (std::isnan(v) ? fill_ : v) * k - z0;  // as load() converts
  const auto vertex = [&](std::size_t i, float v) {
    const int c = static_cast<int>(i % w), r = static_cast<int>(i / w);
    return Eigen::Vector3f(frame_.x(c), frame_.y(r), v * k - z0);
  };
  highest_ = vertex(hi_at, hi);
  lowest_ = vertex(lo_at, lo);
}

std::vector<float> PagedTerrain::load(std::uint64_t key) const {
  const int px = static_cast<int>(key % pages_x_), py = static_cast<int>(key / pages_x_);
  const int c0 = px * page_cells_, c1 = std::min(c0 + page_cells_, frame_.width - 1);
  const int r0 = py * page_cells_, r1 = std::min(r0 + page_cells_, frame_.height - 1);
  std::vector<float> z = reader().read(c0, r0, c1 - c0 + 1, r1 - r0 + 1);
  // As TerrainScene::fill_heights converts a DEM held in core.
  const float k = exaggeration_, z0 = z0_, lo = fill_;
  for (float& v : z) {
    const float h = std::isnan(v) ? lo : v;
    v = h * k - z0;
  }
  // The page: the tree below its blocks, then its heights.
  const std::size_t tree = HeightFieldBlocks::page_tree_floats(page_cells_);
  std::vector<float> out(tree + z.size());
  std::copy(z.begin(), z.end(), out.begin() + static_cast<std::ptrdiff_t>(tree));
  HeightFieldBlocks::page_tree(out.data() + tree, static_cast<std::size_t>(c1 - c0) + 1,
                               page_cells_, c1 - c0, r1 - r0, out.data());
  return out;
}

HeightPage PagedTerrain::page(int page_x, int page_y, std::shared_ptr<const void>& pin) const {
  const std::uint64_t key = static_cast<std::uint64_t>(page_y) * pages_x_ + page_x;
  std::shared_ptr<const BlockCache::Block> block = cache_->get(key);
  const int c0 = page_x * page_cells_, c1 = std::min(c0 + page_cells_, frame_.width - 1);
  const std::size_t tree = HeightFieldBlocks::page_tree_floats(page_cells_);
  HeightPage p{c0,
               page_y * page_cells_,
               static_cast<std::size_t>(c1 - c0 + 1),
               block->data() + tree,
               block->data(),
               page_cells_ / HeightFieldBlocks::kLeaf};
  pin = std::move(block);
  return p;
}

float PagedTerrain::at(int c, int r) const {
  std::shared_ptr<const void> pin;
  const HeightPage p =
      page(std::min(c / page_cells_, pages_x_ - 1), std::min(r / page_cells_, pages_y_ - 1), pin);
  return p.at(c, r);
}

}  // namespace drift::render
