// The bottom of an object over the ground's cells: what the paper's z-buffer
// holds after rendering the object orthographically from below the ground, one
// pixel per cell (paper 000, 3.3, fig. 1). Comparing it with the ground's
// heights gives the stencil of collided cells (bottom < ground) and the
// object's bottom height there.
//
// Two renderers give the same map: a scanline z-buffer on the CPU (float64,
// exact at cell centres) and OSMesa through terrain/offscreen (32-bit float
// depth relative to the object's lowest point, so centimetre prints on a
// 3000 m DEM keep their depth). The CPU one is the default: at the small
// windows an object covers it is far faster (tests/bench/marks_bench.cpp).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <vector>

namespace drift::marks {

// Triangles in the grid's cell space: x = column, y = row (rows run south),
// z = height (m). Three corners per triangle.
using CellTriangles = std::vector<Eigen::Vector3d>;

// A window of cells [col0, col0 + width) x [row0, row0 + height).
struct CellWindow {
  int col0 = 0, row0 = 0, width = 0, height = 0;
  bool empty() const { return width <= 0 || height <= 0; }
  bool contains(int col, int row) const {
    return col >= col0 && row >= row0 && col < col0 + width && row < row0 + height;
  }
};

// The window around triangles' footprint, grown by `margin` cells and clipped
// to a grid of grid_w x grid_h cells (empty if they miss it).
CellWindow footprint_window(const CellTriangles& triangles, int margin, int grid_w, int grid_h);

struct BottomMap {
  static constexpr double kNone = std::numeric_limits<double>::infinity();
  CellWindow window;
  std::vector<double> z;  // per window cell, row-major: lowest object height; kNone: no object

  double at(int col, int row) const {
    return window.contains(col, row)
               ? z[static_cast<std::size_t>(row - window.row0) * window.width + (col - window.col0)]
               : kNone;
  }
};

enum class BottomRenderer { Cpu, OpenGL };

class BottomRasteriser {
 public:
  virtual ~BottomRasteriser() = default;
  // Fills map.z over map.window (set by the caller) with the lowest of the
  // triangles above each cell centre, kNone where there is none.
  void render(const CellTriangles& triangles, BottomMap& map) {
    map.z.assign(static_cast<std::size_t>(map.window.width) * map.window.height, BottomMap::kNone);
    lower(triangles, map);
  }

 private:
  // Lowers map.z (every cell kNone when called) to the triangles' bottom.
  virtual void lower(const CellTriangles& triangles, BottomMap& map) = 0;
};

// Throws drift::Error if OSMesa cannot make a context (OpenGL only).
std::unique_ptr<BottomRasteriser> make_bottom_rasteriser(BottomRenderer kind);

// The object's bottom rendered by OSMesa (paper 000, 3.3: OpenGL looking up
// from below the ground, orthographic, one pixel per cell), through the depth
// renderer shared with snowfall (terrain/offscreen; object_bottom_osmesa.cpp).
// Throws drift::Error if OSMesa cannot make a context. Use on one thread.
std::unique_ptr<BottomRasteriser> make_osmesa_bottom_rasteriser();

}  // namespace drift::marks
