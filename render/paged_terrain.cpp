#include "render/paged_terrain.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "terrain/error.h"
#include "terrain/raster_blocks.h"

namespace drift::render {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kLeaf = HeightFieldBlocks::kLeaf;

}  // namespace

PagedTerrain::PagedTerrain(const std::filesystem::path& dem, std::uint64_t memory_budget,
                           float vertical_exaggeration, int page_cells)
    : reader_(std::make_unique<terrain::RasterBlockReader>(dem)),
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
  try {
    cache_ = std::make_unique<BlockCache>(memory_budget, page_bytes(),
                                          [this](std::uint64_t key) { return load(key); });
  } catch (const Error& e) {
    throw Error(name + ": " + e.what());  // which render's budget, for which DEM
  }
  pages_x_ = (w - 2) / page_cells_ + 1;
  pages_y_ = (h - 2) / page_cells_ + 1;
  frame_.width = w;
  frame_.height = h;
  frame_.dx = static_cast<float>(geo.cell_size_x());
  frame_.dy = static_cast<float>(geo.cell_size_y());
  scan();
}

PagedTerrain::~PagedTerrain() = default;

const terrain::GeoReference& PagedTerrain::geo() const { return reader_->geo(); }

std::uint64_t PagedTerrain::page_bytes() const {
  const std::uint64_t side = static_cast<std::uint64_t>(page_cells_) + 1;
  return side * side * sizeof(float);
}

void PagedTerrain::scan() {
  const int w = frame_.width, h = frame_.height;
  const int cells_x = w - 1, cells_y = h - 1;
  const int leaves_x = (cells_x + kLeaf - 1) / kLeaf, leaves_y = (cells_y + kLeaf - 1) / kLeaf;
  leaves_.assign(static_cast<std::size_t>(leaves_x) * leaves_y, {kInf, -kInf});
  // A strip of page_cells_ rows of cells and its vertices, the last row of
  // one strip carried over as the first of the next (each row read once).
  const int strip = page_cells_;
  std::vector<float> rows(static_cast<std::size_t>(strip + 1) * w);
  float lo = kInf, hi = -kInf;
  std::size_t lo_at = 0, hi_at = 0;
  for (int r0 = 0; r0 < cells_y; r0 += strip) {
    const int r1 = std::min(r0 + strip, cells_y);  // last vertex row of the strip
    const int first_new = r0 == 0 ? 0 : 1;
    if (r0 > 0)
      std::memcpy(rows.data(), rows.data() + static_cast<std::size_t>(strip) * w,
                  sizeof(float) * w);
    const std::vector<float> fresh = reader_->read(0, r0 + first_new, w, r1 - r0 + 1 - first_new);
    std::copy(fresh.begin(), fresh.end(),
              rows.begin() + static_cast<std::ptrdiff_t>(first_new) * w);
    scan_bytes_ += fresh.size() * sizeof(float);
    const auto z = [&](int c, int r) { return rows[static_cast<std::size_t>(r - r0) * w + c]; };
    // Raw min-max of every leaf in the strip (-inf as the lowest: it holds
    // nodata, which becomes the lowest valid height once that is known).
    tbb::parallel_for(r0 / kLeaf, (r1 + kLeaf - 1) / kLeaf, [&](int iy) {
      for (int ix = 0; ix < leaves_x; ++ix) {
        HeightFieldBlocks::MinMax m{kInf, -kInf};
        const int c0 = ix * kLeaf, c1 = std::min(c0 + kLeaf, cells_x);
        const int rr0 = iy * kLeaf, rr1 = std::min(rr0 + kLeaf, cells_y);
        for (int r = rr0; r <= rr1; ++r)
          for (int c = c0; c <= c1; ++c) {
            const float v = z(c, r);
            if (std::isnan(v)) {
              m.lo = -kInf;
            } else {
              m.lo = std::min(m.lo, v), m.hi = std::max(m.hi, v);
            }
          }
        leaves_[static_cast<std::size_t>(iy) * leaves_x + ix] = m;
      }
    });
    // The extremes, the first in row-major order on a tie (vertex rows
    // [r0 + first_new, r1], each once).
    for (int r = r0 + first_new; r <= r1; ++r)
      for (int c = 0; c < w; ++c) {
        const float v = z(c, r);
        if (std::isnan(v)) continue;
        const std::size_t i = static_cast<std::size_t>(r) * w + c;
        if (v < lo) lo = v, lo_at = i;
        if (v > hi) hi = v, hi_at = i;
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
  std::vector<float> z = reader_->read(c0, r0, c1 - c0 + 1, r1 - r0 + 1);
  // As TerrainScene::fill_heights converts a DEM held in core.
  const float k = exaggeration_, z0 = z0_, lo = fill_;
  for (float& v : z) {
    const float h = std::isnan(v) ? lo : v;
    v = h * k - z0;
  }
  return z;
}

HeightPage PagedTerrain::page(int page_x, int page_y, std::shared_ptr<const void>& pin) const {
  const std::uint64_t key = static_cast<std::uint64_t>(page_y) * pages_x_ + page_x;
  std::shared_ptr<const BlockCache::Block> block = cache_->get(key);
  const int c0 = page_x * page_cells_, c1 = std::min(c0 + page_cells_, frame_.width - 1);
  HeightPage p{c0, page_y * page_cells_, static_cast<std::size_t>(c1 - c0 + 1), block->data()};
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
