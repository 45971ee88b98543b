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
// Memory: 4 B a vertex of heights plus the min-max levels, 8 B per kLeaf^2
// cells and a third more above (0.67 B a cell for kLeaf = 4), plus Embree's
// BVH over (cells / kBlock^2) blocks.
#pragma once

#include <Eigen/Core>
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
// page), so every block lies in one page.
struct HeightPage {
  int c0 = 0, r0 = 0;      // the page's first vertex
  std::size_t stride = 0;  // floats a row
  const float* z = nullptr;
  float at(int c, int r) const { return z[static_cast<std::size_t>(r - r0) * stride + (c - c0)]; }
};
class HeightSource {
 public:
  virtual ~HeightSource() = default;
  virtual int page_cells() const = 0;
  // Page (page_x, page_y); `pin` keeps its heights alive while they are read.
  virtual HeightPage page(int page_x, int page_y, std::shared_ptr<const void>& pin) const = 0;
};

class HeightFieldBlocks {
 public:
  struct MinMax {
    float lo, hi;
  };
  static constexpr int kLeaf = 4;                             // cells a side of a min-max leaf
  static constexpr int kBlockLevels = 3;                      // min-max levels inside a block
  static constexpr int kBlock = kLeaf << (kBlockLevels - 1);  // cells a side of a block

  // Builds the min-max levels over `grid` (kept by pointer: it must outlive this).
  explicit HeightFieldBlocks(const HeightGrid& grid);
  // Heights read from `source` instead (`grid` gives the frame; its z stays
  // empty), over leaves min-max computed beforehand (kLeaf x kLeaf cells
  // each, row-major, every vertex of their cells included). Both must
  // outlive this.
  HeightFieldBlocks(const HeightGrid& grid, const HeightSource& source, std::vector<MinMax> leaves);

  // Embree's primitives: blocks of kBlock x kBlock cells (fewer at the east
  // and south edges).
  unsigned block_count() const { return static_cast<unsigned>(blocks_x_ * blocks_y_); }
  void block_bounds(unsigned block, Eigen::Vector3f& lower, Eigen::Vector3f& upper) const;

  // The nearest hit in `block` with tnear < t <= tfar: tfar becomes its
  // distance and `hit` its cell and triangle. False if none.
  bool intersect(unsigned block, const HeightRay& ray, float tnear, float& tfar,
                 HeightHit& hit) const;
  // The same as intersect() over the whole field without the tree and the
  // rows' cell ranges: every cell's two triangles, leaf by leaf, row by row.
  // For tests: the walk must give the same hit, bit for bit.
  bool intersect_every_cell(const HeightRay& ray, float tnear, float& tfar, HeightHit& hit) const;
  // True if the ray meets the block's triangles with tnear < t <= tfar.
  bool occluded(unsigned block, const HeightRay& ray, float tnear, float tfar) const;

  // Bytes of the min-max levels (the heights are the grid's).
  std::size_t bytes() const;

 private:
  struct Level {
    int nx = 0, ny = 0, size = 0;  // nodes a side, cells a node side
    std::vector<MinMax> nodes;
  };
  void size_levels();
  void build_upper_levels();
  // The heights of `block`: the grid's, or its page of the source.
  HeightPage heights_of(unsigned block, std::shared_ptr<const void>& pin) const;
  template <bool kAnyHit>
  bool trace(unsigned block, const HeightPage& page, const HeightRay& ray, float tnear, float& tfar,
             HeightHit& hit) const;
  // The leaf's triangles the ray can meet while inside the leaf's box, which
  // it enters at `enter` and leaves at `exit` (node_entry's distances): only
  // the cells under the ray's path across each row of cells, found from the
  // ray's x at the row's edges, widened by a quarter cell either side.
  template <bool kAnyHit, bool kAllCells>
  bool trace_leaf(int leaf_x, int leaf_y, const HeightPage& page, const HeightRay& ray, float tnear,
                  float& tfar, float enter, float exit, HeightHit& hit) const;
  // The ray's entry and exit distances of node (level, ix, iy) within
  // [tnear, tfar] (widened by the slab slack); false if it misses.
  bool node_entry(int level, int ix, int iy, const HeightRay& ray, float tnear, float tfar,
                  float& entry, float& exit) const;

  const HeightGrid* grid_;
  const HeightSource* source_ = nullptr;  // none: the heights are grid_->z
  int cells_x_ = 0, cells_y_ = 0;
  int blocks_x_ = 0, blocks_y_ = 0;
  std::vector<Level> levels_;  // [0]: leaves of kLeaf cells; the last: blocks
};

}  // namespace drift::render
