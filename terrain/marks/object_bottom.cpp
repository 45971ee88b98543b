#include "terrain/marks/object_bottom.h"

#include <algorithm>
#include <cmath>

namespace drift::marks {

CellWindow footprint_window(const CellTriangles& triangles, int margin, int grid_w, int grid_h) {
  if (triangles.empty()) return {};
  double lo_x = 1e300, hi_x = -1e300, lo_y = 1e300, hi_y = -1e300;
  for (const Eigen::Vector3d& p : triangles) {
    lo_x = std::min(lo_x, p.x()), hi_x = std::max(hi_x, p.x());
    lo_y = std::min(lo_y, p.y()), hi_y = std::max(hi_y, p.y());
  }
  // Clamp in double before converting: a far-away object must not overflow int.
  auto clamp_cell = [](double v, int lo, int hi) {
    return static_cast<int>(std::clamp(v, static_cast<double>(lo), static_cast<double>(hi)));
  };
  const int c0 = clamp_cell(std::floor(lo_x) - margin, 0, grid_w);
  const int c1 = clamp_cell(std::ceil(hi_x) + margin + 1, 0, grid_w);
  const int r0 = clamp_cell(std::floor(lo_y) - margin, 0, grid_h);
  const int r1 = clamp_cell(std::ceil(hi_y) + margin + 1, 0, grid_h);
  return {c0, r0, c1 - c0, r1 - r0};
}

namespace {

// A scanline z-buffer over cell centres: every triangle's plane is evaluated
// at the integer points inside it (edges inclusive, so triangles sharing an
// edge leave no gap); the lowest value wins.
class CpuBottomRasteriser final : public BottomRasteriser {
 private:
  void lower(const CellTriangles& tris, BottomMap& map) override {
    for (std::size_t t = 0; t + 2 < tris.size(); t += 3)
      draw(tris[t], tris[t + 1], tris[t + 2], map);
  }

  static void draw(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   BottomMap& map) {
    const CellWindow& w = map.window;
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    if (std::abs(area) < 1e-12) return;  // seen edge-on from below: no area to cover
    const double s = area > 0 ? 1.0 : -1.0;
    const double eps = 1e-9 * std::abs(area);
    const int x0 = std::max(w.col0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}))));
    const int x1 = std::min(w.col0 + w.width - 1,
                            static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))));
    const int y0 = std::max(w.row0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}))));
    const int y1 = std::min(w.row0 + w.height - 1,
                            static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))));
    if (x0 > x1 || y0 > y1) return;
    // Edge functions and the plane z = z_a + gx (x - a.x) + gy (y - a.y).
    const double gx =
        ((b.z() - a.z()) * (c.y() - a.y()) - (c.z() - a.z()) * (b.y() - a.y())) / area;
    const double gy =
        ((c.z() - a.z()) * (b.x() - a.x()) - (b.z() - a.z()) * (c.x() - a.x())) / area;
    auto edge = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, double x, double y) {
      return (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
    };
    for (int y = y0; y <= y1; ++y) {
      double* row = &map.z[static_cast<std::size_t>(y - w.row0) * w.width];
      for (int x = x0; x <= x1; ++x) {
        if (s * edge(a, b, x, y) < -eps || s * edge(b, c, x, y) < -eps ||
            s * edge(c, a, x, y) < -eps)
          continue;
        const double z = a.z() + gx * (x - a.x()) + gy * (y - a.y());
        row[x - w.col0] = std::min(row[x - w.col0], z);
      }
    }
  }
};

}  // namespace

std::unique_ptr<BottomRasteriser> make_bottom_rasteriser(BottomRenderer kind) {
  if (kind == BottomRenderer::OpenGL) return make_osmesa_bottom_rasteriser();
  return std::make_unique<CpuBottomRasteriser>();
}

}  // namespace drift::marks
