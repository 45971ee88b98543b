#include "terrain/mesh_rtin.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "terrain/error.h"

namespace drift::terrain {

namespace {

constexpr float kMustSplit = std::numeric_limits<float>::infinity();

// A triangle of the tree: hypotenuse a-b, right angle at c.
struct Triangle {
  int ax, ay, bx, by, cx, cy;
};

// Calls f on every triangle `depth` levels below `t`, splitting as Martini's
// numbering does (c a m, then b c m, m the hypotenuse's midpoint), in the
// tree's left-to-right order: neighbours follow each other, and each
// triangle's corners come from its parent's in O(1), where decoding Martini's
// index walked the whole depth for every triangle.
template <class F>
void for_each_at_depth(const Triangle& t, int depth, F& f) {
  if (depth == 0) {
    f(t);
    return;
  }
  const int mx = (t.ax + t.bx) >> 1, my = (t.ay + t.by) >> 1;
  for_each_at_depth(Triangle{t.cx, t.cy, t.ax, t.ay, mx, my}, depth - 1, f);
  for_each_at_depth(Triangle{t.bx, t.by, t.cx, t.cy, mx, my}, depth - 1, f);
}

// Twice the signed area of p, q, r (exact on the grid).
std::int64_t edge(int px, int py, int qx, int qy, int rx, int ry) {
  return static_cast<std::int64_t>(qx - px) * (ry - py) -
         static_cast<std::int64_t>(qy - py) * (rx - px);
}

// Floor and ceiling of n / d for d > 0 (C++ division truncates towards zero).
std::int64_t floor_div(std::int64_t n, std::int64_t d) {
  return n >= 0 ? n / d : -((-n + d - 1) / d);
}
std::int64_t ceil_div(std::int64_t n, std::int64_t d) { return -floor_div(-n, d); }

// Narrows [lo, hi] to the x where s * (p x + q) >= 0 (one edge function along a row).
void clip_span(std::int64_t p, std::int64_t q, int s, std::int64_t& lo, std::int64_t& hi) {
  p *= s, q *= s;
  if (p > 0) {
    lo = std::max(lo, ceil_div(-q, p));
  } else if (p < 0) {
    hi = std::min(hi, floor_div(q, -p));
  } else if (q < 0) {
    hi = lo - 1;  // the whole row lies outside this edge
  }
}

// The largest vertical distance between the heights and the plane of a, b, c
// over every grid point of the closed triangle; kMustSplit where the triangle
// covers a nodata point, or reaches past the grid while overlapping it.
// Returns as soon as the distance exceeds `stop_above` (some value above it,
// not the largest): the tree needs only "above the bound or not" (issue 37: the
// full scan of every triangle made --decimate 3-4 times the full mesh's time).
// Each row is walked over the span its three edge functions allow, solved in
// integers, so the points are exactly those the barycentric test takes.
float triangle_error(const HeightField& h, int ax, int ay, int bx, int by, int cx, int cy,
                     double stop_above = INFINITY) {
  const int w = h.width(), n = h.height();
  const int x0 = std::min({ax, bx, cx}), x1 = std::max({ax, bx, cx});
  const int y0 = std::min({ay, by, cy}), y1 = std::max({ay, by, cy});
  if (x1 > w - 1 || y1 > n - 1) return (x0 < w - 1 && y0 < n - 1) ? kMustSplit : 0.0f;
  const double za = h(ax, ay), zb = h(bx, by), zc = h(cx, cy);
  const std::int64_t area = edge(ax, ay, bx, by, cx, cy);
  const int sense = area > 0 ? 1 : -1;
  double worst = 0.0;
  for (int y = y0; y <= y1; ++y) {
    // edge(p, q, x, y) = (qx - px) (y - py) - (qy - py) (x - px): p x + q in x.
    std::int64_t lo = x0, hi = x1;
    const std::int64_t wa0 = edge(bx, by, cx, cy, 0, y), wb0 = edge(cx, cy, ax, ay, 0, y),
                       wc0 = edge(ax, ay, bx, by, 0, y);
    const std::int64_t pa = -(cy - by), pb = -(ay - cy), pc = -(by - ay);
    clip_span(pa, wa0, sense, lo, hi);
    clip_span(pb, wb0, sense, lo, hi);
    clip_span(pc, wc0, sense, lo, hi);
    for (std::int64_t x = lo; x <= hi; ++x) {
      // Barycentric weights, exact integers over the same area.
      const std::int64_t wa = wa0 + pa * x, wb = wb0 + pb * x, wc = wc0 + pc * x;
      const float z = h(static_cast<int>(x), y);
      if (std::isnan(z)) return kMustSplit;
      const double plane = (za * wa + zb * wb + zc * wc) / static_cast<double>(area);
      worst = std::max(worst, std::abs(z - plane));
    }
    if (worst > stop_above) break;
  }
  return static_cast<float>(worst);
}

bool is_vertex(const HeightField& h, int x, int y) {
  return x < h.width() && y < h.height() && !std::isnan(h(x, y));
}

}  // namespace

RtinMesh rtin_triangles(const HeightField& h, double max_error, const RtinSizeCheck& before_list) {
  if (!(max_error >= 0.0))
    throw Error("--decimate " + std::to_string(max_error) + " must be 0 or more metres");
  if (h.width() < 2 || h.height() < 2)
    throw Error("a grid of " + std::to_string(h.width()) + " x " + std::to_string(h.height()) +
                " cells is too small to mesh; it needs 2 x 2");
  int tile = 2;
  while (tile < std::max(h.width(), h.height()) - 1) tile *= 2;
  const std::int64_t size = tile + 1;
  int deepest = -1;  // the finest triangles' depth: hypotenuse 2 cells, its midpoint a grid point
  for (int t = tile; t > 1; t >>= 1) deepest += 2;
  // errors[m]: the largest error of any triangle whose hypotenuse has its
  // midpoint at m, or of any triangle below those, a level's children before
  // it (the order within a level does not matter: a max); exact up to
  // max_error, and some value above it where the largest is above it.
  std::vector<float> errors(static_cast<std::size_t>(size * size), 0.0f);
  auto at = [size](int x, int y) { return static_cast<std::size_t>(y * size + x); };
  for (int depth = deepest; depth >= 0; --depth) {
    auto update = [&](const Triangle& t) {
      const int mx = (t.ax + t.bx) >> 1, my = (t.ay + t.by) >> 1;
      float e = errors[at(mx, my)];
      if (depth < deepest) {
        e = std::max({e, errors[at((t.ax + t.cx) >> 1, (t.ay + t.cy) >> 1)],
                      errors[at((t.bx + t.cx) >> 1, (t.by + t.cy) >> 1)]});
      }
      // Only "above max_error or not" decides a split: once a triangle below
      // this one (or its twin across the hypotenuse) is above it, this one is
      // too and its own plane need not be measured; else measure it, stopping
      // at the first cell above the bound. The splits are those of the full
      // maxima, so the mesh is the same bit for bit.
      if (!(e > max_error))
        e = std::max(e, triangle_error(h, t.ax, t.ay, t.bx, t.by, t.cx, t.cy, max_error));
      errors[at(mx, my)] = e;
    };
    for_each_at_depth(Triangle{0, 0, tile, tile, tile, 0}, depth, update);
    for_each_at_depth(Triangle{tile, tile, 0, 0, 0, tile}, depth, update);
  }

  RtinMesh out;
  // Splits while the midpoint's error is above the bound and the legs are
  // longer than a cell; calls keep(a, b, c) on the leaves whose corners are all data.
  auto for_each_kept = [&](auto&& keep) {
    auto visit = [&](auto&& self, int ax, int ay, int bx, int by, int cx, int cy) -> void {
      const int mx = (ax + bx) >> 1, my = (ay + by) >> 1;
      if (std::abs(ax - cx) + std::abs(ay - cy) > 1 && errors[at(mx, my)] > max_error) {
        self(self, cx, cy, ax, ay, mx, my);
        self(self, bx, by, cx, cy, mx, my);
        return;
      }
      if (!is_vertex(h, ax, ay) || !is_vertex(h, bx, by) || !is_vertex(h, cx, cy)) return;
      keep(ax, ay, bx, by, cx, cy);
    };
    visit(visit, 0, 0, tile, tile, tile, 0);
    visit(visit, tile, tile, 0, 0, 0, tile);
  };
  {
    // The mesh's size before its list: a walk of the decided tree, far
    // cheaper than deciding it, and a bit a grid point for the vertices.
    std::uint64_t triangles = 0, vertices = 0;
    std::vector<bool> used(static_cast<std::size_t>(h.width()) * h.height(), false);
    const auto mark = [&](int x, int y) {
      const std::size_t i = static_cast<std::size_t>(y) * h.width() + x;
      if (!used[i]) used[i] = true, ++vertices;
    };
    for_each_kept([&](int ax, int ay, int bx, int by, int cx, int cy) {
      ++triangles;
      mark(ax, ay), mark(bx, by), mark(cx, cy);
    });
    if (before_list) before_list(vertices, triangles);
    out.vertices = vertices;
    out.triangles.reserve(triangles);
  }
  for_each_kept([&](int ax, int ay, int bx, int by, int cx, int cy) {
    out.triangles.push_back({{{ax, ay}, {bx, by}, {cx, cy}}});
    out.max_error =
        std::max(out.max_error, static_cast<double>(triangle_error(h, ax, ay, bx, by, cx, cy)));
  });
  if (out.triangles.empty()) throw Error("the raster has no 2 x 2 cells with data to mesh");
  return out;
}

}  // namespace drift::terrain
