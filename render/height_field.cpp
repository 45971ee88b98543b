#include "render/height_field.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>

namespace drift::render {

namespace {

// Box tests widen the slab distances by this share of themselves: a float
// slab distance (b - o) / d is within a few ulps (~1e-7) of the exact one, so
// no ray that meets a triangle inside a box is ever refused by the box.
constexpr float kSlabSlack = 1e-6f;

}  // namespace

HeightRay::HeightRay(const Eigen::Vector3f& o, const Eigen::Vector3f& d) : origin(o), dir(d) {
  for (int a = 0; a < 3; ++a) {
    // A ray parallel to a slab is inside it or not, whatever t (the box test
    // checks that instead of dividing by zero).
    parallel[a] = std::fabs(d[a]) < 1e-30f;
    inv_dir[a] = parallel[a] ? 0.0f : 1.0f / d[a];
  }
  // Woop et al. 2013: z along the largest component, x and y after it,
  // swapped to keep the winding when that component is negative.
  kz = 0;
  if (std::fabs(d.y()) > std::fabs(d[kz])) kz = 1;
  if (std::fabs(d.z()) > std::fabs(d[kz])) kz = 2;
  kx = (kz + 1) % 3;
  ky = (kx + 1) % 3;
  if (d[kz] < 0.0f) std::swap(kx, ky);
  sx = d[kx] / d[kz];
  sy = d[ky] / d[kz];
  sz = 1.0f / d[kz];
}

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
using MinMax = HeightFieldBlocks::MinMax;

void widen(MinMax& m, float z) { m.lo = std::min(m.lo, z), m.hi = std::max(m.hi, z); }

// a + t (b - a) held within [a, b]: t = 0 gives a exactly and rounding never
// leaves the range the bounds were made for.
float mix(float a, float b, float t) {
  return std::clamp(a + t * (b - a), std::min(a, b), std::max(a, b));
}

// A unique stamp a view: a thread's cached LOD blocks of an earlier view (or
// of another field at the same address) never match.
std::atomic<unsigned> lod_views{0};

}  // namespace

void HeightFieldBlocks::size_levels() {
  cells_x_ = grid_->width - 1;
  cells_y_ = grid_->height - 1;
  blocks_x_ = (cells_x_ + kBlock - 1) / kBlock;
  blocks_y_ = (cells_y_ + kBlock - 1) / kBlock;
  groups_x_ = (blocks_x_ + group_ - 1) / group_;
  groups_y_ = (blocks_y_ + group_ - 1) / group_;
  coarse_nx_ = coarse_count(grid_->width);
  coarse_ny_ = coarse_count(grid_->height);
  levels_.resize(kBlockLevels);
  for (int l = 0; l < kBlockLevels; ++l) {
    Level& level = levels_[l];
    level.size = kLeaf << l;
    level.nx = (cells_x_ + level.size - 1) / level.size;
    level.ny = (cells_y_ + level.size - 1) / level.size;
    // Out of core only the blocks' level is held; the rest is in the pages.
    if (!source_ || l == kBlockLevels - 1)
      level.nodes.resize(static_cast<std::size_t>(level.nx) * level.ny);
  }
}

static_assert(QuantisedHeights::kBlock == HeightFieldBlocks::kBlock,
              "16-bit heights are quantised over the height field's blocks");

QuantisedHeights::QuantisedHeights(int width, int height)
    : width_(width),
      height_(height),
      blocks_x_(std::max(1, (width - 1 + kBlock - 1) / kBlock)),
      blocks_y_(std::max(1, (height - 1 + kBlock - 1) / kBlock)),
      q_(static_cast<std::size_t>(width) * height),
      ranges_(static_cast<std::size_t>(blocks_x_) * blocks_y_) {}

QuantisedHeights::QuantisedHeights(const HeightGrid& grid)
    : QuantisedHeights(grid.width, grid.height) {
  tbb::parallel_for(0, blocks_y_, [&](int by) {
    quantise_block_row(by, grid.z.data() + static_cast<std::size_t>(block_row_first(by)) * width_);
  });
}

void QuantisedHeights::quantise_block_row(int by, const float* rows) {
  // The range of the vertices each block owns, then each vertex's nearest
  // step, rounded in double from the float step the decode uses (so
  // |lo + step q - z| <= step / 2 exactly, before the decode's one rounding
  // to float). Only this block row's codes and ranges are written: block
  // rows may be quantised side by side, in any order, from any strips.
  const int r0 = block_row_first(by), r1 = block_row_end(by);
  const auto z = [&](int c, int r) { return rows[static_cast<std::size_t>(r - r0) * width_ + c]; };
  for (int bx = 0; bx < blocks_x_; ++bx) {
    const int c0 = bx * kBlock, c1 = bx == blocks_x_ - 1 ? width_ : c0 + kBlock;
    float lo = kInf, hi = -kInf;
    for (int r = r0; r < r1; ++r)
      for (int c = c0; c < c1; ++c) lo = std::min(lo, z(c, r)), hi = std::max(hi, z(c, r));
    Range& range = ranges_[static_cast<std::size_t>(by) * blocks_x_ + bx];
    range.lo = lo;
    range.step = static_cast<float>((static_cast<double>(hi) - lo) / kSteps);
    for (int r = r0; r < r1; ++r)
      for (int c = c0; c < c1; ++c) {
        const double steps =
            range.step > 0.0f ? (static_cast<double>(z(c, r)) - lo) / range.step : 0.0;
        q_[static_cast<std::size_t>(r) * width_ + c] =
            static_cast<std::uint16_t>(std::clamp(std::nearbyint(steps), 0.0, kSteps));
      }
  }
}

HeightFieldBlocks::HeightFieldBlocks(const HeightGrid& grid) : grid_(&grid) {
  size_levels();
  build_leaves();
  build_upper_levels();
  build_coarse_from_grid();
}

HeightFieldBlocks::HeightFieldBlocks(const HeightGrid& grid, QuantisedHeights heights)
    : grid_(&grid), quantised_(std::move(heights)) {
  if (quantised_.width() != grid.width || quantised_.height() != grid.height)
    throw std::invalid_argument("HeightFieldBlocks: 16-bit heights of another size");
  size_levels();
  build_leaves();
  build_upper_levels();
  build_coarse_from_grid();
}

void HeightFieldBlocks::build_leaves() {
  // Leaves from the heights (every vertex of their cells, edges included),
  // each level above from the one below.
  Level& leaves = levels_[0];
  tbb::parallel_for(0, leaves.ny, [&](int iy) {
    for (int ix = 0; ix < leaves.nx; ++ix) {
      const int c0 = ix * kLeaf, c1 = std::min(c0 + kLeaf, cells_x_);
      const int r0 = iy * kLeaf, r1 = std::min(r0 + kLeaf, cells_y_);
      MinMax m{kInf, -kInf};
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) widen(m, vertex_z(c, r));
      leaves.nodes[static_cast<std::size_t>(iy) * leaves.nx + ix] = m;
    }
  });
}

HeightFieldBlocks::HeightFieldBlocks(const HeightGrid& grid, const HeightSource& source,
                                     std::vector<MinMax> block_bounds, std::vector<float> coarse,
                                     int group)
    : grid_(&grid), source_(&source), group_(std::max(group, 1)) {
  size_levels();
  if (block_bounds.size() != levels_.back().nodes.size() ||
      coarse.size() != static_cast<std::size_t>(coarse_nx_) * coarse_ny_ ||
      source.page_cells() % kBlock != 0)
    throw std::invalid_argument("HeightFieldBlocks: bounds, coarse samples or pages do not fit");
  levels_.back().nodes = std::move(block_bounds);
  coarse_ = std::move(coarse);
}

void HeightFieldBlocks::build_coarse_from_grid() {
  coarse_.resize(static_cast<std::size_t>(coarse_nx_) * coarse_ny_);
  for (int j = 0; j < coarse_ny_; ++j)
    for (int i = 0; i < coarse_nx_; ++i)
      coarse_[static_cast<std::size_t>(j) * coarse_nx_ + i] =
          vertex_z(coarse_vertex(i, grid_->width), coarse_vertex(j, grid_->height));
}

void HeightFieldBlocks::build_upper_levels() {
  for (int l = 1; l < kBlockLevels; ++l) {
    const Level& below = levels_[l - 1];
    Level& level = levels_[l];
    tbb::parallel_for(0, level.ny, [&](int iy) {
      for (int ix = 0; ix < level.nx; ++ix) {
        MinMax m{kInf, -kInf};
        for (int cy = 2 * iy; cy < std::min(2 * iy + 2, below.ny); ++cy)
          for (int cx = 2 * ix; cx < std::min(2 * ix + 2, below.nx); ++cx) {
            const MinMax& b = below.nodes[static_cast<std::size_t>(cy) * below.nx + cx];
            m.lo = std::min(m.lo, b.lo), m.hi = std::max(m.hi, b.hi);
          }
        level.nodes[static_cast<std::size_t>(iy) * level.nx + ix] = m;
      }
    });
  }
}

std::size_t HeightFieldBlocks::page_tree_floats(int page_cells) {
  const std::size_t leaves = static_cast<std::size_t>(page_cells / kLeaf);
  return 2 * (leaves * leaves + (leaves / 2) * (leaves / 2));
}

void HeightFieldBlocks::page_tree(const float* z, std::size_t stride, int page_cells, int cells_x,
                                  int cells_y, float* tree) {
  // As the in-core constructor's leaves (every vertex of a leaf's cells) and
  // the level above them; nodes past the raster's edge stay empty.
  const int n = page_cells / kLeaf, m = n / 2;
  auto* leaves = reinterpret_cast<MinMax*>(tree);
  MinMax* mids = leaves + static_cast<std::size_t>(n) * n;
  std::fill(leaves, mids + static_cast<std::size_t>(m) * m, MinMax{kInf, -kInf});
  for (int iy = 0; iy * kLeaf < cells_y && iy < n; ++iy)
    for (int ix = 0; ix * kLeaf < cells_x && ix < n; ++ix) {
      const int c0 = ix * kLeaf, c1 = std::min(c0 + kLeaf, cells_x);
      const int r0 = iy * kLeaf, r1 = std::min(r0 + kLeaf, cells_y);
      MinMax& leaf = leaves[static_cast<std::size_t>(iy) * n + ix];
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) widen(leaf, z[static_cast<std::size_t>(r) * stride + c]);
      MinMax& mid = mids[static_cast<std::size_t>(iy / 2) * m + ix / 2];
      mid.lo = std::min(mid.lo, leaf.lo), mid.hi = std::max(mid.hi, leaf.hi);
    }
}

std::size_t HeightFieldBlocks::bytes() const {
  std::size_t n = coarse_.size() * sizeof(float) + quantised_.bytes();
  for (const Level& l : levels_) n += l.nodes.size() * sizeof(MinMax);
  return n;
}

void HeightFieldBlocks::set_lod(const LodView& view) {
  lod_ = view;
  const float cell = std::min(grid_->dx, grid_->dy);
  lod_offset_ = view.spread > 0.0f ? std::log2(view.spread / cell) + view.bias : 0.0f;
  lod_generation_ = ++lod_views;
}

// The level at vertex (c, r): log2 of the pixel cone's width there in cells,
// the vertex taken at its level-4 height (a pure function of the vertex and
// the view: the same bits whichever block or ray asks).
float HeightFieldBlocks::lod_level(int c, int r, float h4) const {
  const float dx = grid_->x(c) - lod_.eye.x(), dy = grid_->y(r) - lod_.eye.y();
  const float dz = h4 - lod_.eye.z();
  const float d2 = std::max(dx * dx + dy * dy + dz * dz, 1e-12f);
  return 0.5f * std::log2(d2) + lod_offset_;
}

// The surface through every `spacing`-th vertex (8 or 16, and the last),
// triangulated as the full grid is (diagonal v1-v3), at vertex (c, r): a
// convex combination of the corners whose weight is not zero, so a vertex on
// a coarse cell's edge depends on that edge's corners alone, which every
// block sharing the vertex holds.
float HeightFieldBlocks::coarse_height(int c, int r, int spacing) const {
  const auto cell_of = [&](int v, int cells, int& a, int& b) {
    a = v / spacing * spacing;
    if (a >= cells) a = (cells - 1) / spacing * spacing;
    b = std::min(a + spacing, cells);
  };
  int ca, cb, ra, rb;
  cell_of(c, cells_x_, ca, cb);
  cell_of(r, cells_y_, ra, rb);
  const auto sample = [&](int cc, int rr) {
    const int i = cc % kCoarse == 0 ? cc / kCoarse : coarse_nx_ - 1;
    const int j = rr % kCoarse == 0 ? rr / kCoarse : coarse_ny_ - 1;
    return coarse_[static_cast<std::size_t>(j) * coarse_nx_ + i];
  };
  const float u = static_cast<float>(c - ca) / static_cast<float>(cb - ca);
  const float v = static_cast<float>(r - ra) / static_cast<float>(rb - ra);
  const float h00 = sample(ca, ra), h10 = sample(cb, ra), h01 = sample(ca, rb);
  float h, w0, w1, w2, a, b1, b2;
  if (u + v <= 1.0f) {  // v0 v1 v3
    w0 = 1.0f - u - v, w1 = u, w2 = v, a = h00, b1 = h10, b2 = h01;
    h = h00 + u * (h10 - h00) + v * (h01 - h00);
  } else {  // v2 v3 v1
    const float h11 = sample(cb, rb);
    w0 = u + v - 1.0f, w1 = 1.0f - u, w2 = 1.0f - v, a = h11, b1 = h01, b2 = h10;
    h = h11 + (1.0f - u) * (h01 - h11) + (1.0f - v) * (h10 - h11);
  }
  MinMax m{kInf, -kInf};
  if (w0 > 0.0f) widen(m, a);
  if (w1 > 0.0f) widen(m, b1);
  if (w2 > 0.0f) widen(m, b2);
  if (m.lo > m.hi) return a;  // no weight: cannot happen (the weights sum to 1)
  return std::clamp(h, m.lo, m.hi);
}

// Full resolution below kFullBelow, then morphed to level 3 (every 8th
// vertex) over one level and to level 4 (every 16th) over the next, as CDLOD
// morphs (Strugar 2010), so a vertex's height moves continuously with the
// camera.
float HeightFieldBlocks::lod_height(int c, int r, const HeightPage* page) const {
  const auto full = [&] { return page ? page->at(c, r) : vertex_z(c, r); };
  if (!lod_on()) return full();
  const float h4 = coarse_height(c, r, kBlock);
  const float l = lod_level(c, r, h4);
  if (l >= kFullBelow + 2.0f) return h4;
  const float h3 = coarse_height(c, r, kCoarse);
  if (l >= kFullBelow + 1.0f) return mix(h3, h4, l - (kFullBelow + 1.0f));
  const float h0 = full();
  if (l <= kFullBelow) return h0;
  return mix(h0, h3, l - kFullBelow);
}

float HeightFieldBlocks::height(int c, int r) const {
  if (!source_) return lod_height(c, r, nullptr);
  const int page_cells = source_->page_cells();
  const int pages_x = (cells_x_ - 1) / page_cells + 1, pages_y = (cells_y_ - 1) / page_cells + 1;
  if (lod_on()) {  // no page read where the vertex is coarse
    const float h4 = coarse_height(c, r, kBlock);
    if (lod_level(c, r, h4) >= kFullBelow + 1.0f) return lod_height(c, r, nullptr);
  }
  std::shared_ptr<const void> pin;
  const HeightPage p = source_->page(std::min(c / page_cells, pages_x - 1),
                                     std::min(r / page_cells, pages_y - 1), pin);
  return lod_height(c, r, &p);
}

void HeightFieldBlocks::block_levels(int bx, int by, float& lo, float& hi) const {
  const Level& top = levels_.back();
  const MinMax& m = top.nodes[static_cast<std::size_t>(by) * top.nx + bx];
  const int c0 = bx * kBlock, c1 = std::min(c0 + kBlock, cells_x_);
  const int r0 = by * kBlock, r1 = std::min(r0 + kBlock, cells_y_);
  const float box_lo[3] = {grid_->x(c0), grid_->y(r1), m.lo};
  const float box_hi[3] = {grid_->x(c1), grid_->y(r0), m.hi};
  float near2 = 0, far2 = 0;
  for (int a = 0; a < 3; ++a) {
    const float e = lod_.eye[a];
    const float d = std::max({box_lo[a] - e, e - box_hi[a], 0.0f});
    const float f = std::max(std::fabs(box_lo[a] - e), std::fabs(box_hi[a] - e));
    near2 += d * d, far2 += f * f;
  }
  // 1e-3 of a level is thousands of times the rounding of a vertex's level.
  lo = 0.5f * std::log2(std::max(near2, 1e-12f)) + lod_offset_ - 1e-3f;
  hi = 0.5f * std::log2(std::max(far2, 1e-12f)) + lod_offset_ + 1e-3f;
}

namespace {

constexpr int kBlockVertices = HeightFieldBlocks::kBlock + 1;

// A thread's last LOD blocks (direct-mapped): the heights and tree of a
// block at the level of detail cost 289 vertices' levels, and a block is met
// by many rays. What it holds is a function of the view and the block alone,
// so hits do not depend on what it keeps.
struct LodEntry {
  unsigned generation = 0;
  int bx = -1, by = -1;
  int nx = 0, ny = 0;
  float z[kBlockVertices * kBlockVertices];
  float tree[2 * 21];
};
constexpr std::size_t kLodEntries = 512;

// A block's side x side nodes of one level of its tree (nx x ny nodes, row by
// row), from node (x0, y0); empty ({inf, -inf}) beyond the level's edge.
template <int side>
void block_nodes(const HeightFieldBlocks::MinMax* nodes, int nx, int ny, int x0, int y0,
                 HeightFieldBlocks::MinMax (&out)[side][side]) {
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const int x = x0 + i, y = y0 + j;
      out[j][i] = x < nx && y < ny ? nodes[static_cast<std::size_t>(y) * nx + x]
                                   : HeightFieldBlocks::MinMax{kInf, -kInf};
    }
}

}  // namespace

void HeightFieldBlocks::view_block(int bx, int by, BlockView& view) const {
  const int c0 = bx * kBlock, r0 = by * kBlock;
  const Level& top = levels_.back();
  view.tree.top = top.nodes[static_cast<std::size_t>(by) * top.nx + bx];
  float lo = 0, hi = 0;
  if (lod_on()) block_levels(bx, by, lo, hi);
  const auto page_of_block = [&]() {
    const int blocks_a_page = source_->page_cells() / kBlock;
    return source_->page(bx / blocks_a_page, by / blocks_a_page, view.pin);
  };
  if (!lod_on() || hi < kFullBelow) {  // full resolution: every vertex's height is its own
    if (!source_) {
      view.page = {0, 0, static_cast<std::size_t>(grid_->width), grid_->z.data()};
      if (quantised()) view.page = {0, 0, 0, nullptr, nullptr, 0, &quantised_};
      const Level &leaves = levels_[0], &mids = levels_[1];
      block_nodes(leaves.nodes.data(), leaves.nx, leaves.ny, bx * 4, by * 4, view.tree.leaf);
      block_nodes(mids.nodes.data(), mids.nx, mids.ny, bx * 2, by * 2, view.tree.mid);
      return;
    }
    view.page = page_of_block();
    const int n = view.page.tree_side, m = n / 2;
    const auto* leaves = reinterpret_cast<const MinMax*>(view.page.tree);
    const MinMax* mids = leaves + static_cast<std::size_t>(n) * n;
    const int lx0 = (c0 - view.page.c0) / kLeaf, ly0 = (r0 - view.page.r0) / kLeaf;
    block_nodes(leaves, n, n, lx0, ly0, view.tree.leaf);
    block_nodes(mids, m, m, lx0 / 2, ly0 / 2, view.tree.mid);
    return;
  }
  // At the level of detail: the block's vertices into the view's own page.
  thread_local std::vector<LodEntry> cache(kLodEntries);
  LodEntry& e =
      cache[(static_cast<std::size_t>(by) * 7919u + static_cast<std::size_t>(bx)) % kLodEntries];
  if (e.generation != lod_generation_ || e.bx != bx || e.by != by) {
    HeightPage full;
    std::shared_ptr<const void> pin;
    const bool needs_page = lo < kFullBelow + 1.0f;
    if (needs_page && source_) {
      const int blocks_a_page = source_->page_cells() / kBlock;
      full = source_->page(bx / blocks_a_page, by / blocks_a_page, pin);
    }
    e.nx = std::min(kBlock, cells_x_ - c0) + 1;
    e.ny = std::min(kBlock, cells_y_ - r0) + 1;
    // Only a block with a vertex below level 3 reads its page; elsewhere
    // lod_height never asks for it.
    const HeightPage* page = needs_page && source_ ? &full : nullptr;
    for (int j = 0; j < e.ny; ++j)
      for (int i = 0; i < e.nx; ++i) e.z[j * kBlockVertices + i] = lod_height(c0 + i, r0 + j, page);
    MinMax tree[21];
    std::fill(tree, tree + 21, MinMax{kInf, -kInf});
    for (int j = 0; j < e.ny; ++j)
      for (int i = 0; i < e.nx; ++i) {
        const float z = e.z[j * kBlockVertices + i];
        // Every leaf (and mid node) whose cells have this vertex.
        for (int ly = std::max(0, (j - 1) / kLeaf); ly <= std::min(3, j / kLeaf); ++ly)
          for (int lx = std::max(0, (i - 1) / kLeaf); lx <= std::min(3, i / kLeaf); ++lx) {
            if (lx * kLeaf > i || (lx + 1) * kLeaf < i || ly * kLeaf > j || (ly + 1) * kLeaf < j)
              continue;
            widen(tree[ly * 4 + lx], z);
            widen(tree[16 + (ly / 2) * 2 + lx / 2], z);
          }
        widen(tree[20], z);
      }
    std::memcpy(e.tree, tree, sizeof(tree));
    e.generation = lod_generation_, e.bx = bx, e.by = by;
  }
  std::memcpy(view.z, e.z, sizeof(e.z));
  MinMax tree[21];
  std::memcpy(tree, e.tree, sizeof(tree));
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) view.tree.leaf[j][i] = tree[j * 4 + i];
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) view.tree.mid[j][i] = tree[16 + j * 2 + i];
  view.tree.top = tree[20];
  view.page = {c0, r0, static_cast<std::size_t>(kBlockVertices), view.z};
}

void HeightFieldBlocks::block_bounds(unsigned group, Eigen::Vector3f& lower,
                                     Eigen::Vector3f& upper) const {
  const Level& top = levels_.back();
  const int gx = static_cast<int>(group % groups_x_), gy = static_cast<int>(group / groups_x_);
  const int bx1 = std::min((gx + 1) * group_, blocks_x_),
            by1 = std::min((gy + 1) * group_, blocks_y_);
  MinMax m{kInf, -kInf};
  for (int by = gy * group_; by < by1; ++by)
    for (int bx = gx * group_; bx < bx1; ++bx) {
      const MinMax& b = top.nodes[static_cast<std::size_t>(by) * top.nx + bx];
      m.lo = std::min(m.lo, b.lo), m.hi = std::max(m.hi, b.hi);
    }
  const int c0 = gx * group_ * kBlock, c1 = std::min(bx1 * kBlock, cells_x_);
  const int r0 = gy * group_ * kBlock, r1 = std::min(by1 * kBlock, cells_y_);
  lower = {grid_->x(c0), grid_->y(r1), m.lo};
  upper = {grid_->x(c1), grid_->y(r0), m.hi};
}

bool HeightFieldBlocks::node_entry(int c0, int r0, int size, const MinMax& m, const HeightRay& ray,
                                   float tnear, float tfar, float& entry, float& exit) const {
  const int c1 = std::min(c0 + size, cells_x_), r1 = std::min(r0 + size, cells_y_);
  const float lo[3] = {grid_->x(c0), grid_->y(r1), m.lo};
  const float hi[3] = {grid_->x(c1), grid_->y(r0), m.hi};
  float t0 = tnear, t1 = tfar;
  for (int a = 0; a < 3; ++a) {
    if (ray.parallel[a]) {  // on a face counts as inside: the face's triangles are the box's
      if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a]) return false;
      continue;
    }
    float u = (lo[a] - ray.origin[a]) * ray.inv_dir[a];
    float v = (hi[a] - ray.origin[a]) * ray.inv_dir[a];
    if (u > v) std::swap(u, v);
    t0 = std::max(t0, u - std::fabs(u) * kSlabSlack);
    t1 = std::min(t1, v + std::fabs(v) * kSlabSlack);
  }
  entry = t0;
  exit = t1;
  return t0 <= t1;
}

namespace {

// A vertex in the ray's sheared frame (Woop et al. 2013, eq. 1-2), computed
// by one expression whatever the cell, row, leaf or block that asks for it,
// so that the cells either side of an edge see the same floats.
struct Sheared {
  float x, y, z;
};

Sheared shear(const HeightRay& ray, float x, float y, float z) {
  const float p[3] = {x - ray.origin.x(), y - ray.origin.y(), z - ray.origin.z()};
  return {p[ray.kx] - ray.sx * p[ray.kz], p[ray.ky] - ray.sy * p[ray.kz], ray.sz * p[ray.kz]};
}

// Edge function e(P, Q) = Px Qy - Py Qx, in double: the products of floats
// are exact there and the difference keeps its sign, and e(Q, P) = -e(P, Q)
// exactly, so the two triangles on either side of an edge agree on it.
double edge(const Sheared& p, const Sheared& q) {
  return static_cast<double>(p.x) * q.y - static_cast<double>(p.y) * q.x;
}

// Widening of the cells a ray crosses in a row, in cells: far more than the
// rounding of the ray's x there (a few ulps of the coordinates, 1e-3 of a
// 10 m cell at 100 km), so that every cell whose triangles the exact test
// could accept is tested.
constexpr float kRowPad = 0.25f;
constexpr float kCoordinateUlps = 1e-5f;

}  // namespace

template <bool kAnyHit, bool kAllCells>
bool HeightFieldBlocks::trace_leaf(int leaf_x, int leaf_y, const HeightPage& page,
                                   const HeightRay& ray, float tnear, float& tfar, float enter,
                                   float exit, HeightHit& hit) const {
  constexpr int kV = kLeaf + 1;
  const int c0 = leaf_x * kLeaf, nc = std::min(kLeaf, cells_x_ - c0);
  const int r0 = leaf_y * kLeaf, nr = std::min(kLeaf, cells_y_ - r0);
  const HeightGrid& g = *grid_;
  const float xw = g.x(c0);
  Sheared north[kV], south[kV];  // the row's vertices (rows j and j + 1)
  double vertical[kV];           // e(v(i, j), v(i, j + 1)): west edge of cell i, east of i - 1
  bool found = false;
  for (int j = 0; j < nr; ++j) {
    // The part of [enter, exit] where the ray is over this row of cells
    // (y from y(r + 1) to y(r)), widened by a quarter cell.
    const float yn = g.y(r0 + j), ys = g.y(r0 + j + 1);
    const float pad_y = kRowPad * g.dy + kCoordinateUlps * (std::fabs(yn) + std::fabs(ys));
    float ta = enter, tb = exit;
    int lo = 0, hi = nc - 1;
    if constexpr (kAllCells) {
      // every cell of the row: the reference the walk must match
    } else if (ray.parallel[1]) {
      if (ray.origin.y() < ys - pad_y || ray.origin.y() > yn + pad_y) continue;
    } else {
      float u = (ys - pad_y - ray.origin.y()) * ray.inv_dir[1];
      float v = (yn + pad_y - ray.origin.y()) * ray.inv_dir[1];
      if (u > v) std::swap(u, v);
      ta = std::max(ta, u - std::fabs(u) * kSlabSlack);
      tb = std::min(tb, v + std::fabs(v) * kSlabSlack);
      if (ta > tb) continue;
    }
    if constexpr (!kAllCells) {
      // The columns under the ray there.
      float xa = ray.origin.x(), xb = xa;
      if (!ray.parallel[0]) {
        xa = ray.origin.x() + ta * ray.dir.x();
        xb = ray.origin.x() + tb * ray.dir.x();
        if (xa > xb) std::swap(xa, xb);
      }
      const float slack = kRowPad + kCoordinateUlps * (std::fabs(xa) + std::fabs(xb)) / g.dx;
      const float fa = std::max((xa - xw) / g.dx - slack, -1.0f);
      const float fb = std::min((xb - xw) / g.dx + slack, static_cast<float>(nc));
      if (!(fa <= fb)) continue;
      lo = std::max(0, static_cast<int>(std::floor(fa)));
      hi = std::min(nc - 1, static_cast<int>(std::floor(fb)));
      if (lo > hi) continue;
    }
    for (int i = lo; i <= hi + 1; ++i) {
      north[i] = shear(ray, g.x(c0 + i), yn, page.at(c0 + i, r0 + j));
      south[i] = shear(ray, g.x(c0 + i), ys, page.at(c0 + i, r0 + j + 1));
      vertical[i] = edge(north[i], south[i]);
    }
    for (int i = lo; i <= hi; ++i) {
      const Sheared &p0 = north[i], &p1 = north[i + 1], &p2 = south[i + 1], &p3 = south[i];
      const double top = edge(p0, p1);       // v0 -> v1
      const double bottom = edge(p3, p2);    // v3 -> v2
      const double west = vertical[i];       // v0 -> v3
      const double east = vertical[i + 1];   // v1 -> v2
      const double diagonal = edge(p1, p3);  // v1 -> v3
      // Triangle (A, B, C) has U = -e(B, C), V = -e(C, A), W = -e(A, B).
      for (int tri = 0; tri < 2; ++tri) {
        double u, v, w, az, bz, cz;
        if (tri == 0) {  // v0 v1 v3
          u = -diagonal, v = west, w = -top;
          az = p0.z, bz = p1.z, cz = p3.z;
        } else {  // v2 v3 v1
          u = diagonal, v = -east, w = bottom;
          az = p2.z, bz = p3.z, cz = p1.z;
        }
        if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) continue;
        const double det = u + v + w;
        if (det == 0.0) continue;
        const float t = static_cast<float>((u * az + v * bz + w * cz) / det);
        if (!(t > tnear && t <= tfar)) continue;
        tfar = t;
        hit.cell_x = c0 + i;
        hit.cell_row = r0 + j;
        hit.triangle = tri;
        found = true;
        if constexpr (kAnyHit) return true;
      }
    }
  }
  return found;
}

template <bool kAnyHit>
bool HeightFieldBlocks::trace(int bx, int by, const BlockView& view, const HeightRay& ray,
                              float tnear, float& tfar, HeightHit& hit) const {
  struct Entry {
    int level, lx, ly;  // lx, ly: the node within the block at its level
    float t, exit;
  };
  // Depth-first, nearest child first: at most 3 siblings wait per level.
  Entry stack[4 * kBlockLevels];
  int n = 0;
  const int c0 = bx * kBlock, r0 = by * kBlock;
  float t = 0, exit = 0;
  if (!node_entry(c0, r0, kBlock, view.tree.top, ray, tnear, tfar, t, exit)) return false;
  stack[n++] = {kBlockLevels - 1, 0, 0, t, exit};
  bool found = false;
  while (n > 0) {
    const Entry node = stack[--n];
    if (node.t > tfar) continue;  // a nearer hit was found meanwhile
    if (node.level == 0) {
      if (trace_leaf<kAnyHit, false>(bx * 4 + node.lx, by * 4 + node.ly, view.page, ray, tnear,
                                     tfar, node.t, node.exit, hit)) {
        found = true;
        if constexpr (kAnyHit) return true;
      }
      continue;
    }
    const int size = kLeaf << (node.level - 1);
    Entry children[4];
    int m = 0;
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const int cx = 2 * node.lx + i, cy = 2 * node.ly + j;
        const int cc = c0 + cx * size, rr = r0 + cy * size;
        if (cc >= cells_x_ || rr >= cells_y_) continue;
        const MinMax& b = node.level == 2 ? view.tree.mid[cy][cx] : view.tree.leaf[cy][cx];
        if (node_entry(cc, rr, size, b, ray, tnear, tfar, t, exit))
          children[m++] = {node.level - 1, cx, cy, t, exit};
      }
    // Farthest pushed first, so the nearest is taken next.
    for (int a = 1; a < m; ++a)  // insertion sort of at most 4, farthest first
      for (int b = a; b > 0 && children[b - 1].t < children[b].t; --b)
        std::swap(children[b - 1], children[b]);
    for (int k = 0; k < m; ++k) stack[n++] = children[k];
  }
  return found;
}

template <bool kAnyHit>
bool HeightFieldBlocks::trace_group(unsigned group, const HeightRay& ray, float tnear, float& tfar,
                                    HeightHit& hit) const {
  const int gx = static_cast<int>(group % groups_x_), gy = static_cast<int>(group / groups_x_);
  const int bx1 = std::min((gx + 1) * group_, blocks_x_),
            by1 = std::min((gy + 1) * group_, blocks_y_);
  // The group's blocks the ray meets, nearest first (a group of one: itself).
  struct Candidate {
    float t;
    int bx, by;
  };
  Candidate candidates[64];
  int n = 0;
  const Level& top = levels_.back();
  for (int by = gy * group_; by < by1; ++by)
    for (int bx = gx * group_; bx < bx1; ++bx) {
      float t = 0, exit = 0;
      if (node_entry(bx * kBlock, by * kBlock, kBlock,
                     top.nodes[static_cast<std::size_t>(by) * top.nx + bx], ray, tnear, tfar, t,
                     exit))
        candidates[n++] = {t, bx, by};
    }
  std::sort(candidates, candidates + n, [](const Candidate& a, const Candidate& b) {
    return a.t < b.t || (a.t == b.t && (a.by < b.by || (a.by == b.by && a.bx < b.bx)));
  });
  bool found = false;
  thread_local BlockView view;
  for (int k = 0; k < n; ++k) {
    if (candidates[k].t > tfar) break;
    const int bx = candidates[k].bx, by = candidates[k].by;
    view_block(bx, by, view);
    if (!trace<kAnyHit>(bx, by, view, ray, tnear, tfar, hit)) continue;
    found = true;
    if constexpr (kAnyHit) break;
    const int c = hit.cell_x, r = hit.cell_row;
    const auto vertex = [&](int cc, int rr) {
      return Eigen::Vector3f(grid_->x(cc), grid_->y(rr), view.page.at(cc, rr));
    };
    const Eigen::Vector3f v0 = vertex(c, r), v1 = vertex(c + 1, r);
    const Eigen::Vector3f v2 = vertex(c + 1, r + 1), v3 = vertex(c, r + 1);
    hit.ng = hit.triangle == 0 ? Eigen::Vector3f((v1 - v0).cross(v3 - v0))
                               : Eigen::Vector3f((v3 - v2).cross(v1 - v2));
  }
  view.pin.reset();
  return found;
}

bool HeightFieldBlocks::intersect(unsigned block, const HeightRay& ray, float tnear, float& tfar,
                                  HeightHit& hit) const {
  return trace_group<false>(block, ray, tnear, tfar, hit);
}

bool HeightFieldBlocks::intersect_every_cell(const HeightRay& ray, float tnear, float& tfar,
                                             HeightHit& hit) const {
  bool found = false;
  BlockView view;
  for (int by = 0; by < blocks_y_; ++by)
    for (int bx = 0; bx < blocks_x_; ++bx) {
      view_block(bx, by, view);
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
          const int lx = bx * 4 + i, ly = by * 4 + j;
          if (lx * kLeaf >= cells_x_ || ly * kLeaf >= cells_y_) continue;
          found |= trace_leaf<false, true>(lx, ly, view.page, ray, tnear, tfar, tnear, tfar, hit);
        }
    }
  return found;
}

bool HeightFieldBlocks::occluded(unsigned block, const HeightRay& ray, float tnear,
                                 float tfar) const {
  HeightHit hit;
  return trace_group<true>(block, ray, tnear, tfar, hit);
}

}  // namespace drift::render
