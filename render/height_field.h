// The terrain as the renderer holds it: one float a vertex (the DEM's cell
// centres), traced exactly as the triangulation Embree's grid geometry gives
// (each cell v0 = (c, r), v1 = (c + 1, r), v2 = (c + 1, r + 1), v3 = (c, r + 1)
// split along v1-v3 into triangles v0 v1 v3 and v2 v3 v1, as Embree's quads
// are; rtcNewGeometry(3), RTC_GEOMETRY_TYPE_GRID and RTC_GEOMETRY_TYPE_QUAD)
// but without its 12 B float3 vertex and ~20 B of grid BVH a vertex.
//
// Embree's grid geometry cannot read heights alone: its vertex buffer is
// RTC_FORMAT_FLOAT3 (x, y, z a vertex; a stride only steps between rows of
// vertices). So the terrain is an Embree user geometry (RTC_GEOMETRY_TYPE_USER)
// of square blocks of cells, Embree's BVH over the blocks, and inside a block
// a min-max quadtree of the heights (Tevs et al. 2008, "Maximum mipmaps for
// fast, accurate, and scalable dynamic height field rendering") down to
// leaves of kLeaf x kLeaf cells, whose triangles are intersected with Woop,
// Benthin and Wald's watertight test (JCGT 2(1), 2013): neighbouring
// triangles share each edge function bit for bit, so no ray slips between
// them, whatever the cell, leaf or block boundary.
//
// Memory: 4 B a vertex of heights (2 B with QuantisedHeights) plus the min-max levels, 8 B per
// kLeaf^2 cells and a third more above (0.67 B a cell for kLeaf = 4), plus Embree's BVH over (cells
// / kBlock^2) blocks.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace drift::render {

// Heights of a north-up raster in the scene's local frame.
struct HeightGrid {
  int width = 0, height = 0;  // vertices
  float x0 = 0, y0 = 0;       // local position of vertex (0, 0), the north-west one
  float dx = 1, dy = 1;       // spacing; row r lies at y0 - r dy (rows run south)
  std::vector<float> z;       // local heights, row-major, row 0 north

  // The same expressions the float3 vertex buffer was filled with, so both
  // geometries place every vertex on the same floats.
  float x(int c) const { return x0 + static_cast<float>(c) * dx; }
  float y(int r) const { return y0 - static_cast<float>(r) * dy; }
  float at(int c, int r) const { return z[static_cast<std::size_t>(r) * width + c]; }
  Eigen::Vector3f vertex(int c, int r) const { return {x(c), y(r), at(c, r)}; }
};

// 16-bit heights (issue 36 item 1; `drift render --height-bits 16`): every
// vertex an unsigned 16-bit step over the range of the block of kBlock x
// kBlock cells that owns it (vertex (c, r) belongs to block (c / kBlock,
// r / kBlock), the last row and column to the last block), 2 B a vertex and
// 8 B a block in place of 4 B a vertex. A vertex is decoded with its owner's
// range whichever block reads it, so the blocks either side of an edge meet
// the same floats and the watertight test keeps its guarantee.
//
// Error bound: a height is within half a step, (hi - lo) / 65535 / 2 of its
// owner's range, of the float it was given, plus half an ulp of the decoded
// float (the decode rounds once, from double): 7.6 mm for a block of 1,000 m
// of relief, 0.15 mm for one of 20 m (QuantisedHeights.ErrorIsWithinHalfAStep).
class QuantisedHeights {
 public:
  static constexpr int kBlock = 16;  // HeightFieldBlocks::kBlock (checked there)
  static constexpr double kSteps = 65535.0;
  struct Range {
    float lo = 0.0f, step = 0.0f;  // height = lo + step q
  };

  QuantisedHeights() = default;
  // Quantises grid.z (grid.width x grid.height vertices, no NaN).
  explicit QuantisedHeights(const HeightGrid& grid);
  // width x height vertices, all codes 0, to be quantised block row by block
  // row (quantise_block_row) as the heights are read, so that the floats of
  // a strip, never of the whole raster, exist at once (issue 36;
  // TerrainScene's streamed 16-bit scene): the same codes and ranges as the
  // constructor above gives for the same floats.
  QuantisedHeights(int width, int height);
  int block_rows() const { return blocks_y_; }
  // Block row by owns vertex rows [block_row_first(by), block_row_end(by)).
  int block_row_first(int by) const { return by * kBlock; }
  int block_row_end(int by) const { return by == blocks_y_ - 1 ? height_ : (by + 1) * kBlock; }
  // Quantises block row `by` from `rows`, its vertex rows (width() floats
  // each, no NaN); block rows may be quantised concurrently.
  void quantise_block_row(int by, const float* rows);

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return q_.empty(); }
  // The block owning vertex (c, r), row-major over blocks_x() x blocks_y().
  std::size_t owner(int c, int r) const {
    return static_cast<std::size_t>(std::min(r / kBlock, blocks_y_ - 1)) * blocks_x_ +
           static_cast<std::size_t>(std::min(c / kBlock, blocks_x_ - 1));
  }
  const Range& range(std::size_t block) const { return ranges_[block]; }
  std::uint16_t code(int c, int r) const { return q_[static_cast<std::size_t>(r) * width_ + c]; }
  float at(int c, int r) const {
    const Range& b = ranges_[owner(c, r)];
    return static_cast<float>(static_cast<double>(b.lo) +
                              static_cast<double>(b.step) * static_cast<double>(code(c, r)));
  }
  std::size_t bytes() const {
    return q_.size() * sizeof(std::uint16_t) + ranges_.size() * sizeof(Range);
  }

 private:
  int width_ = 0, height_ = 0, blocks_x_ = 0, blocks_y_ = 0;
  std::vector<std::uint16_t> q_;  // row-major, row 0 north
  std::vector<Range> ranges_;     // by owner block
};

// A ray prepared once for every block it meets: its inverse direction for the
// box tests and the shear of Woop et al.'s watertight triangle test.
struct HeightRay {
  Eigen::Vector3f origin, dir, inv_dir;
  bool parallel[3];            // dir[a] is 0: the ray stays in one plane of that axis
  int kx = 0, ky = 1, kz = 2;  // dir's largest component is kz
  float sx = 0, sy = 0, sz = 1;
  HeightRay(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir);
};

// A hit on the height field: the cell, which of its two triangles, and the
// triangle's geometric normal (not normalised; it points down, as Embree's
// Ng of the grid does: rows run south).
struct HeightHit {
  int cell_x = 0, cell_row = 0;
  int triangle = 0;  // 0: v0 v1 v3, 1: v2 v3 v1
  Eigen::Vector3f ng{0, 0, -1};
};

// Where the heights of a block come from when they are not all in memory
// (render/paged_terrain.h reads them on demand; issue 36 item 2): square pages
// of page_cells() cells, a multiple of HeightFieldBlocks::kBlock, each holding
// its (page_cells() + 1)^2 vertices (one shared row and column with the next
// page), so every block lies in one page, and the lower levels of the
// min-max tree over them (HeightFieldBlocks::page_tree: the tree below the
// blocks lives in the pages, not in memory).
struct HeightPage {
  int c0 = 0, r0 = 0;      // the page's first vertex
  std::size_t stride = 0;  // floats a row
  const float* z = nullptr;
  const float* tree = nullptr;          // page_tree()'s nodes (none: the tree is in memory)
  int tree_side = 0;                    // leaves a side of the page (page_cells / kLeaf)
  const QuantisedHeights* q = nullptr;  // 16-bit heights in core (then z is unused)
  float at(int c, int r) const {
    return q ? q->at(c, r) : z[static_cast<std::size_t>(r - r0) * stride + (c - c0)];
  }
};
class HeightSource {
 public:
  virtual ~HeightSource() = default;
  virtual int page_cells() const = 0;
  // Page (page_x, page_y); `pin` keeps its heights alive while they are read.
  virtual HeightPage page(int page_x, int page_y, std::shared_ptr<const void>& pin) const = 0;
};

// The level of detail of a frame (issue 36 item 2; docs/rendering.md, "Level
// of detail by footprint"): where the camera's pixel cone is wider than a few
// cells the surface's vertices slide onto coarser surfaces (every 8th and
// every 16th vertex, triangulated as the full grid is), continuously with
// the distance, so that no ray needs the full-resolution page of a distant
// block and nothing pops as the camera moves. A vertex's height depends on
// the vertex and the view alone (never on the ray or the cache), so shared
// edges agree bit for bit (no cracks) and shadow and bounce rays meet the
// surface the camera rays met.
struct LodView {
  Eigen::Vector3f eye{0, 0, 0};  // the camera (local frame)
  float spread = 0.0f;           // the pixel cone's width a metre (radians a pixel); 0: off
  float bias = 0.0f;             // added to the level (>0: coarser sooner)
};

class HeightFieldBlocks {
 public:
  struct MinMax {
    float lo, hi;
  };
  static constexpr int kLeaf = 4;                             // cells a side of a min-max leaf
  static constexpr int kBlockLevels = 3;                      // min-max levels inside a block
  static constexpr int kBlock = kLeaf << (kBlockLevels - 1);  // cells a side of a block
  // The coarse levels' spacing: level 3 takes every 8th vertex, level 4
  // every 16th (kBlock: a block's corners), so every coarse cell a block's
  // vertices interpolate lies in the block and the block's min-max bounds
  // the coarse surfaces too.
  static constexpr int kCoarse = 8;
  // The level (log2 of the footprint in cells) below which a vertex is at
  // full resolution; from there it morphs to level 3 by kFullBelow + 1 and
  // to level 4 by kFullBelow + 2.
  static constexpr float kFullBelow = 2.0f;

  // Builds the min-max levels over `grid` (kept by pointer: it must outlive this).
  explicit HeightFieldBlocks(const HeightGrid& grid);
  // Heights read from `source` instead (`grid` gives the frame; its z stays
  // empty): in memory only the blocks' min-max (kBlock x kBlock cells each,
  // row-major, every vertex of their cells included) and the coarse samples
  // (coarse_columns() x coarse_rows(), row-major; see coarse_sample());
  // the tree below the blocks comes with each page (page_tree). `grid` and
  // `source` must outlive this. `group`: blocks a side of one Embree
  // primitive (Embree's BVH then holds group^2 times fewer primitives).
  // Over 16-bit heights (`grid` gives the frame; its z may be empty): the
  // tree bounds the decoded heights, which are what rays meet.
  HeightFieldBlocks(const HeightGrid& grid, QuantisedHeights heights);
  bool quantised() const { return !quantised_.empty(); }
  HeightFieldBlocks(const HeightGrid& grid, const HeightSource& source,
                    std::vector<MinMax> block_bounds, std::vector<float> coarse, int group = 1);

  // The coarse samples' grid: vertex columns 0, 8, 16, ... and the last.
  static int coarse_count(int vertices) { return (vertices - 2) / kCoarse + 2; }
  // The vertex of coarse index i (of `vertices` a side).
  static int coarse_vertex(int i, int vertices) { return std::min(i * kCoarse, vertices - 1); }
  // The tree below the blocks of a page of `page_cells` cells whose heights
  // are `z` (`stride` floats a row, cells_x x cells_y cells of it real):
  // page_tree_floats(page_cells) floats.
  static std::size_t page_tree_floats(int page_cells);
  static void page_tree(const float* z, std::size_t stride, int page_cells, int cells_x,
                        int cells_y, float* tree);

  // The frame's level of detail (not while rays are traced). Off by default.
  void set_lod(const LodView& view);
  bool lod_on() const { return lod_.spread > 0.0f; }
  // Vertex (c, r)'s height as the rays meet it (the level of detail's).
  float height(int c, int r) const;

  // Embree's primitives: groups of group x group blocks of kBlock x kBlock
  // cells (fewer at the east and south edges).
  unsigned block_count() const { return static_cast<unsigned>(groups_x_ * groups_y_); }
  void block_bounds(unsigned block, Eigen::Vector3f& lower, Eigen::Vector3f& upper) const;

  // The nearest hit in primitive `block` with tnear < t <= tfar: tfar becomes its
  // distance and `hit` its cell and triangle. False if none.
  bool intersect(unsigned block, const HeightRay& ray, float tnear, float& tfar,
                 HeightHit& hit) const;
  // The same as intersect() over the whole field without the tree and the
  // rows' cell ranges: every cell's two triangles, leaf by leaf, row by row.
  // For tests: the walk must give the same hit, bit for bit.
  bool intersect_every_cell(const HeightRay& ray, float tnear, float& tfar, HeightHit& hit) const;
  // True if the ray meets the block's triangles with tnear < t <= tfar.
  bool occluded(unsigned block, const HeightRay& ray, float tnear, float tfar) const;

  // Bytes of the min-max levels and coarse samples held in memory (the
  // heights are the grid's or the pages').
  std::size_t bytes() const;

 private:
  struct Level {
    int nx = 0, ny = 0, size = 0;  // nodes a side, cells a node side
    std::vector<MinMax> nodes;
  };
  // One block's tree, local: [0] 4 x 4 leaves, [1] 2 x 2, [2] the block.
  struct BlockTree {
    MinMax leaf[4][4], mid[2][2], top;
  };
  // A block's heights and tree as one trace reads them.
  struct BlockView {
    HeightPage page;
    BlockTree tree;
    std::shared_ptr<const void> pin;
    float z[(kBlock + 1) * (kBlock + 1)];  // the level of detail's heights (page.z then)
  };
  void size_levels();
  void build_leaves();
  void build_upper_levels();
  // Vertex (c, r)'s full-resolution height in core (float or 16-bit).
  float vertex_z(int c, int r) const {
    return quantised_.empty() ? grid_->at(c, r) : quantised_.at(c, r);
  }
  void build_coarse_from_grid();
  // The heights and tree of block (bx, by): the grid's, its page's, or the
  // level of detail's (computed from the coarse samples and, near the
  // camera, the page).
  void view_block(int bx, int by, BlockView& view) const;
  float lod_level(int c, int r, float h4) const;
  float coarse_height(int c, int r, int spacing) const;
  float lod_height(int c, int r, const HeightPage* page) const;
  // The level's range over the box of block (bx, by), widened by more than
  // its rounding: lo above 3 needs no page, hi below kFullBelow is full resolution.
  void block_levels(int bx, int by, float& lo, float& hi) const;
  template <bool kAnyHit>
  bool trace(int bx, int by, const BlockView& view, const HeightRay& ray, float tnear, float& tfar,
             HeightHit& hit) const;
  template <bool kAnyHit>
  bool trace_group(unsigned group, const HeightRay& ray, float tnear, float& tfar,
                   HeightHit& hit) const;
  // The leaf's triangles the ray can meet while inside the leaf's box, which
  // it enters at `enter` and leaves at `exit` (node_entry's distances): only
  // the cells under the ray's path across each row of cells, found from the
  // ray's x at the row's edges, widened by a quarter cell either side.
  template <bool kAnyHit, bool kAllCells>
  bool trace_leaf(int leaf_x, int leaf_y, const HeightPage& page, const HeightRay& ray, float tnear,
                  float& tfar, float enter, float exit, HeightHit& hit) const;
  // The ray's entry and exit distances of the box of cells [c0, c0 + size) x
  // [r0, r0 + size) (clipped to the field) between heights m within [tnear,
  // tfar] (widened by the slab slack); false if it misses.
  bool node_entry(int c0, int r0, int size, const MinMax& m, const HeightRay& ray, float tnear,
                  float tfar, float& entry, float& exit) const;

  const HeightGrid* grid_;
  const HeightSource* source_ = nullptr;  // none: the heights are grid_->z or quantised_
  QuantisedHeights quantised_;            // empty: float heights
  int cells_x_ = 0, cells_y_ = 0;
  int blocks_x_ = 0, blocks_y_ = 0;
  int group_ = 1, groups_x_ = 0, groups_y_ = 0;
  std::vector<Level> levels_;  // [0]: leaves of kLeaf cells; the last: blocks (paged: only it)
  std::vector<float> coarse_;  // every kCoarse-th vertex and the last, row-major
  int coarse_nx_ = 0, coarse_ny_ = 0;
  LodView lod_;
  float lod_offset_ = 0.0f;      // log2(spread / cell) + bias
  unsigned lod_generation_ = 0;  // tells a thread's cached LOD blocks from an earlier view's
};

}  // namespace drift::render
