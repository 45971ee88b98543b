// Small meshes and grounds for the marks tests.
#pragma once

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
