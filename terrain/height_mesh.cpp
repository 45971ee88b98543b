#include "terrain/height_mesh.h"

#include <algorithm>
#include <cmath>

#include "terrain/error.h"
#include "terrain/mesh_io.h"

namespace drift::terrain {

RasterWindow crop_window(const RasterHeader& header, const std::array<double, 4>& box,
                         const std::string& name) {
  const GeoReference& g = header.geo;
  if (!g.north_up())
    throw Error("raster '" + name + "' is rotated; --crop needs a north-up raster");
  // Columns and rows whose cell centres lie inside the box.
  const auto col = [&](double x) { return (x - g.geotransform[0]) / g.geotransform[1] - 0.5; };
  const auto row = [&](double y) { return (y - g.geotransform[3]) / g.geotransform[5] - 0.5; };
  const double c0 = std::min(col(box[0]), col(box[2])), c1 = std::max(col(box[0]), col(box[2]));
  const double r0 = std::min(row(box[1]), row(box[3])), r1 = std::max(row(box[1]), row(box[3]));
  const int x0 = std::max(0, static_cast<int>(std::ceil(c0)));
  const int x1 = std::min(header.width - 1, static_cast<int>(std::floor(c1)));
  const int y0 = std::max(0, static_cast<int>(std::ceil(r0)));
  const int y1 = std::min(header.height - 1, static_cast<int>(std::floor(r1)));
  if (x1 - x0 < 1 || y1 - y0 < 1) {
    throw Error("--crop " + std::to_string(box[0]) + "," + std::to_string(box[1]) + "," +
                std::to_string(box[2]) + "," + std::to_string(box[3]) +
                " holds fewer than 2 x 2 cells of raster '" + name +
                "'; give xmin,ymin,xmax,ymax in its own CRS (drift info shows its extent)");
  }
  return {x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

Mesh height_field_mesh(const HeightField& h, int step,
                       const std::vector<std::pair<std::string, HeightField>>& attributes) {
  if (step < 1) throw Error("internal: height_field_mesh step " + std::to_string(step));
  for (const auto& [name, a] : attributes) {
    if (a.width() != h.width() || a.height() != h.height() ||
        a.geo().geotransform != h.geo().geotransform) {
      throw Error("attribute raster '" + name + "' is " + std::to_string(a.width()) + " x " +
                  std::to_string(a.height()) + " cells on its own grid; it must share the " +
                  std::to_string(h.width()) + " x " + std::to_string(h.height()) +
                  " grid of the heights (drift import --crop the same box)");
    }
  }
  // The columns and rows kept: every step-th and the last.
  auto kept = [step](int n) {
    std::vector<int> k;
    for (int i = 0; i < n; i += step) k.push_back(i);
    if (k.back() != n - 1) k.push_back(n - 1);
    return k;
  };
  const std::vector<int> cols = kept(h.width()), rows = kept(h.height());
  const GeoReference& g = h.geo();
  const std::array<double, 2> o = g.cell_center(0, 0);
  Mesh mesh;
  mesh.origin = {o[0], o[1], 0.0};
  for (const auto& [name, a] : attributes)
    mesh.vertex_attributes.emplace_back(name, std::vector<float>{});
  const std::size_t nc = cols.size();
  const bool flip = g.geotransform[1] * g.geotransform[5] > 0;
  std::vector<int> index(nc * rows.size(), -1);
  // At most a vertex a kept cell and two triangles a square: reserved, so the
  // memory is what mesh_and_write_bytes counts, not up to twice it by doubling.
  mesh.positions.reserve(index.size());
  for (auto& [name, values] : mesh.vertex_attributes) values.reserve(index.size());
  mesh.triangles.reserve(2 * (nc - 1) * (rows.size() - 1));
  auto vertex = [&](std::size_t i, std::size_t j) {  // column i, row j of the kept ones
    int& v = index[j * nc + i];
    if (v >= 0) return v;
    const int x = cols[i], r = rows[j];
    const std::array<double, 2> p = g.cell_center(x, r);
    v = static_cast<int>(mesh.positions.size());
    mesh.positions.emplace_back(static_cast<float>(p[0] - o[0]), static_cast<float>(p[1] - o[1]),
                                h(x, r));
    for (std::size_t k = 0; k < attributes.size(); ++k)
      mesh.vertex_attributes[k].second.push_back(attributes[k].second(x, r));
    return v;
  };
  for (std::size_t j = 0; j + 1 < rows.size(); ++j) {
    for (std::size_t i = 0; i + 1 < nc; ++i) {
      const float a = h(cols[i], rows[j]), b = h(cols[i + 1], rows[j]), c = h(cols[i], rows[j + 1]),
                  d = h(cols[i + 1], rows[j + 1]);
      if (std::isnan(a) || std::isnan(b) || std::isnan(c) || std::isnan(d)) continue;
      // Rows run south in a north-up raster: (i, j+1) is south of (i, j), so
      // nw, sw, se then nw, se, ne are counter-clockwise seen from above.
      const int nw = vertex(i, j), ne = vertex(i + 1, j), sw = vertex(i, j + 1),
                se = vertex(i + 1, j + 1);
      if (flip) {  // a south-up raster: rows run north
        mesh.triangles.push_back({nw, se, sw});
        mesh.triangles.push_back({nw, ne, se});
      } else {
        mesh.triangles.push_back({nw, sw, se});
        mesh.triangles.push_back({nw, se, ne});
      }
    }
  }
  if (mesh.triangles.empty()) throw Error("the raster has no 2 x 2 cells with data to mesh");
  mesh.normals = vertex_normals(mesh);
  return mesh;
}

}  // namespace drift::terrain
