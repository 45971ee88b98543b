// The RTIN simplification (terrain/mesh_rtin.h) behind drift mesh --decimate:
// the vertical error bound holds at every cell centre, the triangles tile the
// grid without cracks or overlaps, nodata is never covered, a plane needs two
// triangles, and the mesh is counter-clockwise from above like the full one.
#include "terrain/mesh_rtin.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>

#include "terrain/error.h"
#include "terrain/height_mesh.h"

using drift::terrain::GridTriangle;
using drift::terrain::HeightField;
using drift::terrain::rtin_triangles;

namespace {

// Rough ground of w x h cells: ridges, a cliff and hashed noise of +-0.3 m.
HeightField rough(int w, int h) {
  HeightField g(w, h, 0.0f);
  for (int r = 0; r < h; ++r) {
    for (int x = 0; x < w; ++x) {
      std::uint32_t k =
          static_cast<std::uint32_t>(x) * 73856093u ^ static_cast<std::uint32_t>(r) * 19349663u;
      k = (k ^ (k >> 13)) * 0x5bd1e995u;
      const double noise = ((k >> 8) & 0xffff) / 65535.0 - 0.5;
      g(x, r) = static_cast<float>(20.0 * std::sin(x * 0.21) * std::cos(r * 0.17) +
                                   (x > w / 2 ? 8.0 : 0.0) + 0.6 * noise);
    }
  }
  return g;
}

std::int64_t cross(const GridTriangle& t) {
  return static_cast<std::int64_t>(t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) -
         static_cast<std::int64_t>(t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
}

// Over every grid point each triangle covers: the largest |height - plane|,
// how many triangles cover each point's interior (area-weighted tiling check:
// the areas must add up to the grid's), and whether nodata is covered.
struct Check {
  double max_error = 0.0;
  double area = 0.0;  // in cells
  bool covers_nodata = false;
};

Check check(const HeightField& g, const std::vector<GridTriangle>& tris) {
  Check c;
  for (const GridTriangle& t : tris) {
    const std::int64_t a2 = cross(t);
    c.area += std::abs(a2) / 2.0;
    const int x0 = std::min({t[0][0], t[1][0], t[2][0]}),
              x1 = std::max({t[0][0], t[1][0], t[2][0]});
    const int y0 = std::min({t[0][1], t[1][1], t[2][1]}),
              y1 = std::max({t[0][1], t[1][1], t[2][1]});
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        double w[3];
        for (int k = 0; k < 3; ++k) {
          const auto& p = t[(k + 1) % 3];
          const auto& q = t[(k + 2) % 3];
          w[k] = static_cast<double>(static_cast<std::int64_t>(q[0] - p[0]) * (y - p[1]) -
                                     static_cast<std::int64_t>(q[1] - p[1]) * (x - p[0])) /
                 static_cast<double>(a2);
        }
        if (w[0] < 0 || w[1] < 0 || w[2] < 0) continue;
        if (std::isnan(g(x, y))) {
          c.covers_nodata = true;
          continue;
        }
        double plane = 0;
        for (int k = 0; k < 3; ++k) plane += w[k] * g(t[k][0], t[k][1]);
        c.max_error = std::max(c.max_error, std::abs(g(x, y) - plane));
      }
    }
  }
  return c;
}

// A vertex strictly inside another triangle's edge is a crack (a T-junction).
int t_junctions(const std::vector<GridTriangle>& tris) {
  std::set<std::pair<int, int>> vertices;
  for (const GridTriangle& t : tris)
    for (const auto& p : t) vertices.insert({p[0], p[1]});
  int found = 0;
  for (const GridTriangle& t : tris) {
    for (int k = 0; k < 3; ++k) {
      const auto& p = t[k];
      const auto& q = t[(k + 1) % 3];
      const int n = std::max(std::abs(q[0] - p[0]), std::abs(q[1] - p[1]));  // axis or diagonal
      for (int s = 1; s < n; ++s) {
        found += vertices.count({p[0] + (q[0] - p[0]) / n * s, p[1] + (q[1] - p[1]) / n * s});
      }
    }
  }
  return found;
}

}  // namespace

TEST(MeshRtin, ErrorBoundHoldsAtEveryCellAndTilesWithoutCracks) {
  for (const auto& [w, h] : {std::pair{33, 33}, std::pair{37, 23}, std::pair{64, 9}}) {
    const HeightField g = rough(w, h);
    std::size_t previous = SIZE_MAX;
    for (const double bound : {0.0, 0.1, 0.5, 2.0, 10.0}) {
      const auto r = rtin_triangles(g, bound);
      const Check c = check(g, r.triangles);
      SCOPED_TRACE(std::to_string(w) + " x " + std::to_string(h) + " bound " +
                   std::to_string(bound));
      EXPECT_LE(c.max_error, bound + 1e-4);
      EXPECT_NEAR(r.max_error, c.max_error, 1e-4);
      EXPECT_DOUBLE_EQ(c.area, static_cast<double>(w - 1) * (h - 1));  // no holes, no overlaps
      EXPECT_EQ(t_junctions(r.triangles), 0);
      EXPECT_LE(r.triangles.size(), previous);  // a looser bound never needs more
      previous = r.triangles.size();
    }
    EXPECT_LT(rtin_triangles(g, 2.0).triangles.size(), rtin_triangles(g, 0.0).triangles.size() / 2);
  }
}

TEST(MeshRtin, APlaneIsTwoTrianglesAndNodataIsNeverCovered) {
  HeightField plane(33, 33, 0.0f);
  for (int r = 0; r < 33; ++r)
    for (int x = 0; x < 33; ++x) plane(x, r) = 3.0f * x - 0.5f * r;
  EXPECT_EQ(rtin_triangles(plane, 0.0).triangles.size(), 2u);

  HeightField holed = rough(30, 20);
  for (int r = 5; r < 9; ++r)
    for (int x = 10; x < 13; ++x) holed(x, r) = NAN;
  const auto r = rtin_triangles(holed, 1.0);
  const Check c = check(holed, r.triangles);
  EXPECT_FALSE(c.covers_nodata);
  EXPECT_LE(c.max_error, 1.0 + 1e-4);
  EXPECT_EQ(t_junctions(r.triangles), 0);
  // The cells around the hole are gone, the rest covered: (29 x 19) cells less
  // the 5 x 6 touching the hole, give or take the halves of its edge cells.
  EXPECT_GT(c.area, 29.0 * 19 - 5 * 6 - 1e-9);
  EXPECT_LT(c.area, 29.0 * 19 - 2 * 3);
  EXPECT_THROW(rtin_triangles(holed, -1.0), drift::Error);
  EXPECT_THROW(rtin_triangles(HeightField(1, 5, 0.0f), 1.0), drift::Error);
}

TEST(MeshRtin, DecimatedMeshIsCounterClockwiseFromAboveOnTheCellCentres) {
  HeightField g = rough(37, 23);
  g.geo().geotransform = {700000.0, 10.0, 0.0, 4000300.0, 0.0, -10.0};
  double measured = -1;
  const drift::terrain::Mesh m = drift::terrain::decimated_height_field_mesh(g, 0.5, {}, &measured);
  EXPECT_GT(measured, 0.0);
  EXPECT_LE(measured, 0.5);
  const drift::terrain::Mesh full = drift::terrain::height_field_mesh(g, 1);
  EXPECT_LT(m.triangle_count(), full.triangle_count());
  for (const auto& t : m.triangles) {
    const Eigen::Vector3f n =
        (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]);
    ASSERT_GT(n.z(), 0.0f);
  }
  // Vertices are cell centres in metres from the first cell's, heights as stored.
  EXPECT_EQ(m.origin, full.origin);
  for (const auto& p : m.positions) {
    const int x = static_cast<int>(std::lround(p.x() / 10.0)),
              r = static_cast<int>(std::lround(-p.y() / 10.0));
    EXPECT_FLOAT_EQ(p.z(), g(x, r));
  }
}

namespace reference {

// The straightforward RTIN as first written (issue 37): Martini's index
// decoded per triangle and every triangle's error measured over its whole
// box. The fast version must keep the very same triangles and error.
constexpr float kMustSplit = INFINITY;

// A grid point.
struct Point {
  int x, y;
};

// Twice the signed area of p, q, r: exact in integers.
std::int64_t cross(Point p, Point q, Point r) {
  return static_cast<std::int64_t>(q.x - p.x) * (r.y - p.y) -
         static_cast<std::int64_t>(q.y - p.y) * (r.x - p.x);
}

// Every grid point of the closed triangle a b c (the three cross products
// never of opposite signs), its height against the plane through the
// corners. A triangle reaching past the grid must split while it still
// overlaps the grid, and is dropped once it lies wholly beyond.
float triangle_error(const HeightField& h, Point a, Point b, Point c) {
  const Point lo{std::min({a.x, b.x, c.x}), std::min({a.y, b.y, c.y})};
  const Point hi{std::max({a.x, b.x, c.x}), std::max({a.y, b.y, c.y})};
  if (hi.x >= h.width() || hi.y >= h.height())
    return lo.x + 1 < h.width() && lo.y + 1 < h.height() ? kMustSplit : 0.0f;
  const double area = static_cast<double>(cross(a, b, c));
  const double za = h(a.x, a.y), zb = h(b.x, b.y), zc = h(c.x, c.y);
  double worst = 0.0;
  for (Point p = lo; p.y <= hi.y; ++p.y) {
    for (p.x = lo.x; p.x <= hi.x; ++p.x) {
      const std::int64_t wa = cross(b, c, p), wb = cross(c, a, p), wc = cross(a, b, p);
      if (std::min({wa, wb, wc}) < 0 && std::max({wa, wb, wc}) > 0) continue;
      if (std::isnan(h(p.x, p.y))) return kMustSplit;
      worst = std::max(worst, std::abs(h(p.x, p.y) - (za * wa + zb * wb + zc * wc) / area));
    }
  }
  return static_cast<float>(worst);
}

drift::terrain::RtinMesh rtin(const HeightField& h, double max_error) {
  int tile = 2;
  while (tile < std::max(h.width(), h.height()) - 1) tile *= 2;
  const std::int64_t size = tile + 1;
  const std::int64_t triangles = 2 * static_cast<std::int64_t>(tile) * tile - 2;
  const std::int64_t parents = triangles - static_cast<std::int64_t>(tile) * tile;
  std::vector<float> errors(static_cast<std::size_t>(size * size), 0.0f);
  auto at = [size](int x, int y) { return static_cast<std::size_t>(y * size + x); };
  for (std::int64_t i = triangles - 1; i >= 0; --i) {
    std::int64_t id = i + 2;
    int ax = 0, ay = 0, bx = 0, by = 0, cx = 0, cy = 0;
    if (id & 1) {
      bx = by = cx = tile;
    } else {
      ax = ay = cy = tile;
    }
    while ((id >>= 1) > 1) {
      const int mx = (ax + bx) >> 1, my = (ay + by) >> 1;
      if (id & 1) {
        bx = ax, by = ay;
        ax = cx, ay = cy;
      } else {
        ax = bx, ay = by;
        bx = cx, by = cy;
      }
      cx = mx, cy = my;
    }
    const int mx = (ax + bx) >> 1, my = (ay + by) >> 1;
    float e = std::max(errors[at(mx, my)], triangle_error(h, {ax, ay}, {bx, by}, {cx, cy}));
    if (i < parents) {
      e = std::max({e, errors[at((ax + cx) >> 1, (ay + cy) >> 1)],
                    errors[at((bx + cx) >> 1, (by + cy) >> 1)]});
    }
    errors[at(mx, my)] = e;
  }
  // The leaves, depth first by a stack of triangles (hypotenuse a-b, right
  // angle at c), a child c a m before b c m.
  struct Triangle {
    Point a, b, c;
  };
  std::vector<Triangle> stack = {{{tile, tile}, {0, 0}, {0, tile}},
                                 {{0, 0}, {tile, tile}, {tile, 0}}};
  const auto is_vertex = [&h](Point p) {
    return p.x < h.width() && p.y < h.height() && !std::isnan(h(p.x, p.y));
  };
  drift::terrain::RtinMesh out;
  while (!stack.empty()) {
    const Triangle t = stack.back();
    stack.pop_back();
    const Point m{(t.a.x + t.b.x) >> 1, (t.a.y + t.b.y) >> 1};
    const bool legs_longer_than_a_cell = std::abs(t.a.x - t.c.x) + std::abs(t.a.y - t.c.y) > 1;
    if (legs_longer_than_a_cell && errors[at(m.x, m.y)] > max_error) {
      stack.push_back({t.b, t.c, m});
      stack.push_back({t.c, t.a, m});
    } else if (is_vertex(t.a) && is_vertex(t.b) && is_vertex(t.c)) {
      out.triangles.push_back({{{t.a.x, t.a.y}, {t.b.x, t.b.y}, {t.c.x, t.c.y}}});
      out.max_error =
          std::max(out.max_error, static_cast<double>(triangle_error(h, t.a, t.b, t.c)));
    }
  }
  return out;
}

}  // namespace reference

// The speed-up (errors measured only up to the bound, rows walked over their
// spans, the tree walked level by level) keeps the mesh bit for bit: on rough
// ground of three shapes, with holes of nodata, at bounds 0..10 m, the same
// triangles in the same order and the same largest error as the plain version.
TEST(MeshRtin, FastTreeKeepsThePlainVersionsTrianglesExactly) {
  for (const auto& [w, h] : {std::pair{33, 33}, std::pair{37, 23}, std::pair{64, 9}}) {
    HeightField g = rough(w, h);
    for (int r = 0; r < h; ++r)
      for (int x = 0; x < w; ++x)
        if ((x - w / 3) * (x - w / 3) + (r - h / 2) * (r - h / 2) < 5 || (x == w - 2 && r == 1))
          g(x, r) = NAN;
    for (double bound : {0.0, 0.05, 0.3, 1.0, 4.0, 10.0}) {
      SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h) + " bound " + std::to_string(bound));
      const auto fast = rtin_triangles(g, bound);
      const auto plain = reference::rtin(g, bound);
      ASSERT_EQ(fast.triangles.size(), plain.triangles.size());
      EXPECT_TRUE(fast.triangles == plain.triangles);
      EXPECT_EQ(fast.max_error, plain.max_error);
    }
  }
}
