#include "render/height_field.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
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

void HeightFieldBlocks::size_levels() {
  cells_x_ = grid_->width - 1;
  cells_y_ = grid_->height - 1;
  blocks_x_ = (cells_x_ + kBlock - 1) / kBlock;
  blocks_y_ = (cells_y_ + kBlock - 1) / kBlock;
  levels_.resize(kBlockLevels);
  for (int l = 0; l < kBlockLevels; ++l) {
    Level& level = levels_[l];
    level.size = kLeaf << l;
    level.nx = (cells_x_ + level.size - 1) / level.size;
    level.ny = (cells_y_ + level.size - 1) / level.size;
    level.nodes.resize(static_cast<std::size_t>(level.nx) * level.ny);
  }
}

HeightFieldBlocks::HeightFieldBlocks(const HeightGrid& grid) : grid_(&grid) {
  size_levels();
  // Leaves from the heights (every vertex of their cells, edges included),
  // each level above from the one below.
  Level& leaves = levels_[0];
  tbb::parallel_for(0, leaves.ny, [&](int iy) {
    for (int ix = 0; ix < leaves.nx; ++ix) {
      const int c0 = ix * kLeaf, c1 = std::min(c0 + kLeaf, cells_x_);
      const int r0 = iy * kLeaf, r1 = std::min(r0 + kLeaf, cells_y_);
      MinMax m{std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) {
          const float z = grid.at(c, r);
          m.lo = std::min(m.lo, z), m.hi = std::max(m.hi, z);
        }
      leaves.nodes[static_cast<std::size_t>(iy) * leaves.nx + ix] = m;
    }
  });
  build_upper_levels();
}

HeightFieldBlocks::HeightFieldBlocks(const HeightGrid& grid, const HeightSource& source,
                                     std::vector<MinMax> leaves)
    : grid_(&grid), source_(&source) {
  size_levels();
  if (leaves.size() != levels_[0].nodes.size() || source.page_cells() % kBlock != 0)
    throw std::invalid_argument("HeightFieldBlocks: leaves or pages do not fit the grid");
  levels_[0].nodes = std::move(leaves);
  build_upper_levels();
}

void HeightFieldBlocks::build_upper_levels() {
  for (int l = 1; l < kBlockLevels; ++l) {
    const Level& below = levels_[l - 1];
    Level& level = levels_[l];
    tbb::parallel_for(0, level.ny, [&](int iy) {
      for (int ix = 0; ix < level.nx; ++ix) {
        MinMax m{std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
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

HeightPage HeightFieldBlocks::heights_of(unsigned block, std::shared_ptr<const void>& pin) const {
  if (!source_) return {0, 0, static_cast<std::size_t>(grid_->width), grid_->z.data()};
  const int blocks_a_page = source_->page_cells() / kBlock;
  const int bx = static_cast<int>(block % blocks_x_), by = static_cast<int>(block / blocks_x_);
  return source_->page(bx / blocks_a_page, by / blocks_a_page, pin);
}

std::size_t HeightFieldBlocks::bytes() const {
  std::size_t n = 0;
  for (const Level& l : levels_) n += l.nodes.size() * sizeof(MinMax);
  return n;
}

void HeightFieldBlocks::block_bounds(unsigned block, Eigen::Vector3f& lower,
                                     Eigen::Vector3f& upper) const {
  const Level& top = levels_.back();
  const int ix = static_cast<int>(block % blocks_x_), iy = static_cast<int>(block / blocks_x_);
  const int c0 = ix * kBlock, c1 = std::min(c0 + kBlock, cells_x_);
  const int r0 = iy * kBlock, r1 = std::min(r0 + kBlock, cells_y_);
  const MinMax& m = top.nodes[static_cast<std::size_t>(iy) * top.nx + ix];
  lower = {grid_->x(c0), grid_->y(r1), m.lo};
  upper = {grid_->x(c1), grid_->y(r0), m.hi};
}

bool HeightFieldBlocks::node_entry(int level, int ix, int iy, const HeightRay& ray, float tnear,
                                   float tfar, float& entry, float& exit) const {
  const Level& l = levels_[level];
  const int c0 = ix * l.size, c1 = std::min(c0 + l.size, cells_x_);
  const int r0 = iy * l.size, r1 = std::min(r0 + l.size, cells_y_);
  const MinMax& m = l.nodes[static_cast<std::size_t>(iy) * l.nx + ix];
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
bool HeightFieldBlocks::trace(unsigned block, const HeightPage& page, const HeightRay& ray,
                              float tnear, float& tfar, HeightHit& hit) const {
  struct Entry {
    int level, ix, iy;
    float t, exit;
  };
  // Depth-first, nearest child first: at most 3 siblings wait per level.
  Entry stack[4 * kBlockLevels];
  int n = 0;
  const int top = kBlockLevels - 1;
  const int bx = static_cast<int>(block % blocks_x_), by = static_cast<int>(block / blocks_x_);
  float t = 0, exit = 0;
  if (!node_entry(top, bx, by, ray, tnear, tfar, t, exit)) return false;
  stack[n++] = {top, bx, by, t, exit};
  bool found = false;
  while (n > 0) {
    const Entry node = stack[--n];
    if (node.t > tfar) continue;  // a nearer hit was found meanwhile
    if (node.level == 0) {
      if (trace_leaf<kAnyHit, false>(node.ix, node.iy, page, ray, tnear, tfar, node.t, node.exit,
                                     hit)) {
        found = true;
        if constexpr (kAnyHit) return true;
      }
      continue;
    }
    const Level& below = levels_[node.level - 1];
    Entry children[4];
    int m = 0;
    for (int cy = 2 * node.iy; cy < std::min(2 * node.iy + 2, below.ny); ++cy)
      for (int cx = 2 * node.ix; cx < std::min(2 * node.ix + 2, below.nx); ++cx)
        if (node_entry(node.level - 1, cx, cy, ray, tnear, tfar, t, exit))
          children[m++] = {node.level - 1, cx, cy, t, exit};
    // Farthest pushed first, so the nearest is taken next.
    for (int a = 1; a < m; ++a)  // insertion sort of at most 4, farthest first
      for (int b = a; b > 0 && children[b - 1].t < children[b].t; --b)
        std::swap(children[b - 1], children[b]);
    for (int k = 0; k < m; ++k) stack[n++] = children[k];
  }
  return found;
}

bool HeightFieldBlocks::intersect(unsigned block, const HeightRay& ray, float tnear, float& tfar,
                                  HeightHit& hit) const {
  std::shared_ptr<const void> pin;
  const HeightPage page = heights_of(block, pin);
  if (!trace<false>(block, page, ray, tnear, tfar, hit)) return false;
  const int c = hit.cell_x, r = hit.cell_row;
  const auto vertex = [&](int cc, int rr) {
    return Eigen::Vector3f(grid_->x(cc), grid_->y(rr), page.at(cc, rr));
  };
  const Eigen::Vector3f v0 = vertex(c, r), v1 = vertex(c + 1, r);
  const Eigen::Vector3f v2 = vertex(c + 1, r + 1), v3 = vertex(c, r + 1);
  hit.ng = hit.triangle == 0 ? Eigen::Vector3f((v1 - v0).cross(v3 - v0))
                             : Eigen::Vector3f((v3 - v2).cross(v1 - v2));
  return true;
}

bool HeightFieldBlocks::intersect_every_cell(const HeightRay& ray, float tnear, float& tfar,
                                             HeightHit& hit) const {
  bool found = false;
  constexpr int kLeavesABlock = kBlock / kLeaf;
  for (int ly = 0; ly < levels_[0].ny; ++ly)
    for (int lx = 0; lx < levels_[0].nx; ++lx) {
      const auto block =
          static_cast<unsigned>((ly / kLeavesABlock) * blocks_x_ + lx / kLeavesABlock);
      std::shared_ptr<const void> pin;
      const HeightPage page = heights_of(block, pin);
      found |= trace_leaf<false, true>(lx, ly, page, ray, tnear, tfar, tnear, tfar, hit);
    }
  return found;
}

bool HeightFieldBlocks::occluded(unsigned block, const HeightRay& ray, float tnear,
                                 float tfar) const {
  HeightHit hit;
  std::shared_ptr<const void> pin;
  const HeightPage page = heights_of(block, pin);
  return trace<true>(block, page, ray, tnear, tfar, hit);
}

}  // namespace drift::render
