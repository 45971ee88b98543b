#include "terrain/mesh_rtin.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "terrain/error.h"

namespace drift::terrain {

namespace {

constexpr float kMustSplit = std::numeric_limits<float>::infinity();

// Triangle `i` of the tree: hypotenuse a-b, right angle at c (Martini's
// numbering: the two halves of the square first, then each level's
// children, so a triangle's children come after it).
struct Triangle {
  int ax, ay, bx, by, cx, cy;
};

Triangle tree_triangle(std::int64_t i, int tile) {
  std::int64_t id = i + 2;
  Triangle t{0, 0, 0, 0, 0, 0};
  if (id & 1) {
    t.bx = t.by = t.cx = tile;  // a = (0, 0), b = (tile, tile), c = (tile, 0)
  } else {
    t.ax = t.ay = t.cy = tile;  // a = (tile, tile), b = (0, 0), c = (0, tile)
  }
  while ((id >>= 1) > 1) {
    const int mx = (t.ax + t.bx) >> 1, my = (t.ay + t.by) >> 1;
    if (id & 1) {  // the half on a's side of the median
      t.bx = t.ax, t.by = t.ay;
      t.ax = t.cx, t.ay = t.cy;
    } else {
      t.ax = t.bx, t.ay = t.by;
      t.bx = t.cx, t.by = t.cy;
    }
    t.cx = mx, t.cy = my;
  }
  return t;
}

// Twice the signed area of p, q, r (exact on the grid).
std::int64_t edge(int px, int py, int qx, int qy, int rx, int ry) {
  return static_cast<std::int64_t>(qx - px) * (ry - py) -
         static_cast<std::int64_t>(qy - py) * (rx - px);
}

// The largest vertical distance between the heights and the plane of a, b, c
// over every grid point of the closed triangle; kMustSplit where the triangle
// covers a nodata point, or reaches past the grid while overlapping it.
float triangle_error(const HeightField& h, int ax, int ay, int bx, int by, int cx, int cy) {
  const int w = h.width(), n = h.height();
  const int x0 = std::min({ax, bx, cx}), x1 = std::max({ax, bx, cx});
  const int y0 = std::min({ay, by, cy}), y1 = std::max({ay, by, cy});
  if (x1 > w - 1 || y1 > n - 1) return (x0 < w - 1 && y0 < n - 1) ? kMustSplit : 0.0f;
  const double za = h(ax, ay), zb = h(bx, by), zc = h(cx, cy);
  const std::int64_t area = edge(ax, ay, bx, by, cx, cy);
  double worst = 0.0;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      // Barycentric weights, exact integers over the same area.
      const std::int64_t wa = edge(bx, by, cx, cy, x, y), wb = edge(cx, cy, ax, ay, x, y),
                         wc = edge(ax, ay, bx, by, x, y);
      const bool inside =
          area > 0 ? (wa >= 0 && wb >= 0 && wc >= 0) : (wa <= 0 && wb <= 0 && wc <= 0);
      if (!inside) continue;
      const float z = h(x, y);
      if (std::isnan(z)) return kMustSplit;
      const double plane = (za * wa + zb * wb + zc * wc) / static_cast<double>(area);
      worst = std::max(worst, std::abs(z - plane));
    }
  }
  return static_cast<float>(worst);
}

bool is_vertex(const HeightField& h, int x, int y) {
  return x < h.width() && y < h.height() && !std::isnan(h(x, y));
}

}  // namespace

RtinMesh rtin_triangles(const HeightField& h, double max_error) {
  if (!(max_error >= 0.0))
    throw Error("--decimate " + std::to_string(max_error) + " must be 0 or more metres");
  if (h.width() < 2 || h.height() < 2)
    throw Error("a grid of " + std::to_string(h.width()) + " x " + std::to_string(h.height()) +
                " cells is too small to mesh; it needs 2 x 2");
  int tile = 2;
  while (tile < std::max(h.width(), h.height()) - 1) tile *= 2;
  const std::int64_t size = tile + 1;
  const std::int64_t triangles = 2 * static_cast<std::int64_t>(tile) * tile - 2;
  const std::int64_t parents = triangles - static_cast<std::int64_t>(tile) * tile;
  // errors[m]: the largest error of any triangle whose hypotenuse has its
  // midpoint at m, or of any triangle below those; children first.
  std::vector<float> errors(static_cast<std::size_t>(size * size), 0.0f);
  auto at = [size](int x, int y) { return static_cast<std::size_t>(y * size + x); };
  for (std::int64_t i = triangles - 1; i >= 0; --i) {
    const Triangle t = tree_triangle(i, tile);
    const int mx = (t.ax + t.bx) >> 1, my = (t.ay + t.by) >> 1;
    float e = std::max(errors[at(mx, my)], triangle_error(h, t.ax, t.ay, t.bx, t.by, t.cx, t.cy));
    if (i < parents) {
      e = std::max({e, errors[at((t.ax + t.cx) >> 1, (t.ay + t.cy) >> 1)],
                    errors[at((t.bx + t.cx) >> 1, (t.by + t.cy) >> 1)]});
    }
    errors[at(mx, my)] = e;
  }

  RtinMesh out;
  // Splits while the midpoint's error is above the bound and the legs are
  // longer than a cell; keeps the leaves whose corners are all data.
  auto visit = [&](auto&& self, int ax, int ay, int bx, int by, int cx, int cy) -> void {
    const int mx = (ax + bx) >> 1, my = (ay + by) >> 1;
    if (std::abs(ax - cx) + std::abs(ay - cy) > 1 && errors[at(mx, my)] > max_error) {
      self(self, cx, cy, ax, ay, mx, my);
      self(self, bx, by, cx, cy, mx, my);
      return;
    }
    if (!is_vertex(h, ax, ay) || !is_vertex(h, bx, by) || !is_vertex(h, cx, cy)) return;
    out.triangles.push_back({{{ax, ay}, {bx, by}, {cx, cy}}});
    out.max_error =
        std::max(out.max_error, static_cast<double>(triangle_error(h, ax, ay, bx, by, cx, cy)));
  };
  visit(visit, 0, 0, tile, tile, tile, 0);
  visit(visit, tile, tile, 0, 0, 0, tile);
  if (out.triangles.empty()) throw Error("the raster has no 2 x 2 cells with data to mesh");
  return out;
}

}  // namespace drift::terrain
