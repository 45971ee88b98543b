// Small meshes and grounds for the marks tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "terrain/grid.h"
#include "terrain/marks/marks.h"
#include "terrain/mesh.h"

namespace drift::marks::testing {

// A UV sphere about the origin, triangles counter-clockwise seen from outside.
inline terrain::Mesh sphere(double radius, int rings = 24, int segments = 48) {
  terrain::Mesh m;
  for (int i = 0; i <= rings; ++i) {
    const double theta = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * std::numbers::pi * j / segments;
      m.positions.emplace_back(radius * std::sin(theta) * std::cos(phi),
                               radius * std::sin(theta) * std::sin(phi), radius * std::cos(theta));
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = i * segments + j, b = i * segments + (j + 1) % segments;
      const int c = a + segments, d = b + segments;
      if (i > 0) m.triangles.push_back({a, c, b});
      if (i < rings - 1) m.triangles.push_back({b, c, d});
    }
  return m;
}

// An axis-aligned box about the origin with half sizes hx, hy, hz, triangles
// counter-clockwise seen from outside.
inline terrain::Mesh box(double hx, double hy, double hz) {
  terrain::Mesh m;
  for (int i = 0; i < 8; ++i)
    m.positions.emplace_back(i & 1 ? hx : -hx, i & 2 ? hy : -hy, i & 4 ? hz : -hz);
  // Faces as corner quads (a, b, c, d) counter-clockwise from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

// An upturned cup: a square roof (half size `half`, 5 mm thick, its underside
// at z = 0) on four walls 1 cm thick reaching down to z = -depth. Its contact
// encloses a hole under the roof.
inline terrain::Mesh cup(double half, double depth) {
  terrain::Mesh m;
  auto add = [&](double hx, double hy, double hz, double cx, double cy, double cz) {
    const terrain::Mesh b = box(hx, hy, hz);
    const int base = static_cast<int>(m.positions.size());
    for (const auto& p : b.positions) m.positions.emplace_back(p.x() + cx, p.y() + cy, p.z() + cz);
    for (const auto& t : b.triangles)
      m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  };
  const double w = 0.005;  // half a wall
  add(half, half, 0.0025, 0, 0, 0.0025);
  add(w, half, depth / 2, -half + w, 0, -depth / 2);
  add(w, half, depth / 2, half - w, 0, -depth / 2);
  add(half, w, depth / 2, 0, -half + w, -depth / 2);
  add(half, w, depth / 2, 0, half - w, -depth / 2);
  return m;
}

// The object's bottom at `pose` over the whole field (kNone where it is not).
inline BottomMap bottom_at(const ObjectShape& shape, const Pose& pose, const MarksSimulation& sim) {
  const CellTriangles t = posed_triangles(shape, pose, sim.frame());
  BottomMap b;
  b.window = {0, 0, sim.heights().width(), sim.heights().height()};
  make_bottom_rasteriser(BottomRenderer::Cpu)->render(t, b);
  return b;
}

// The largest height of ground above the bottom (m; <= 0: none inside).
inline double inside(const BottomMap& b, const terrain::Grid<double>& h) {
  double worst = -1e300;
  for (int r = 0; r < h.height(); ++r)
    for (int c = 0; c < h.width(); ++c)
      if (std::isfinite(b.at(c, r))) worst = std::max(worst, h(c, r) - b.at(c, r));
  return worst;
}

// A flat ground of n x n cells of `cell` metres at height `z`.
inline terrain::HeightField flat(int n, double cell, float z) {
  return terrain::HeightField(n, n, z, terrain::local_georeference(cell));
}

inline double volume(const terrain::Grid<double>& h, double cell) {
  double v = 0;
  for (double x : h.values()) v += x;
  return v * cell * cell;
}

// World position of cell (col, row)'s centre at height z.
inline Eigen::Vector3d at_cell(const MarksSimulation& s, double col, double row, double z) {
  return s.frame().to_world(col, row, z);
}

inline MaterialField only(const std::string& preset) {
  MaterialField f;
  f.table = {*material_preset(preset)};
  return f;
}

}  // namespace drift::marks::testing
