#include "terrain/height_mesh.h"

#include <algorithm>
#include <cmath>

#include "terrain/error.h"
#include "terrain/mesh_io.h"
#include "terrain/mesh_rtin.h"

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

namespace {

void require_same_grid(const HeightField& h,
                       const std::vector<std::pair<std::string, HeightField>>& attributes) {
  for (const auto& [name, a] : attributes) {
    if (a.width() != h.width() || a.height() != h.height() ||
        a.geo().geotransform != h.geo().geotransform) {
      throw Error("attribute raster '" + name + "' is " + std::to_string(a.width()) + " x " +
                  std::to_string(a.height()) + " cells on its own grid; it must share the " +
                  std::to_string(h.width()) + " x " + std::to_string(h.height()) +
                  " grid of the heights (drift import --crop the same box)");
    }
  }
}

// The mesh's vertices, one per grid point a triangle uses, made on first use:
// metres from the first cell's centre, with the attributes' values there.
class GridVertices {
 public:
  GridVertices(Mesh& mesh, const HeightField& h,
               const std::vector<std::pair<std::string, HeightField>>& attributes)
      : mesh_(mesh),
        h_(h),
        attributes_(attributes),
        origin_(h.geo().cell_center(0, 0)),
        index_(static_cast<std::size_t>(h.width()) * h.height(), -1) {
    mesh.origin = {origin_[0], origin_[1], 0.0};
    for (const auto& [name, a] : attributes)
      mesh.vertex_attributes.emplace_back(name, std::vector<float>{});
  }

  int operator()(int x, int r) {
    int& v = index_[static_cast<std::size_t>(r) * h_.width() + x];
    if (v >= 0) return v;
    const std::array<double, 2> p = h_.geo().cell_center(x, r);
    v = static_cast<int>(mesh_.positions.size());
    mesh_.positions.emplace_back(static_cast<float>(p[0] - origin_[0]),
                                 static_cast<float>(p[1] - origin_[1]), h_(x, r));
    for (std::size_t k = 0; k < attributes_.size(); ++k)
      mesh_.vertex_attributes[k].second.push_back(attributes_[k].second(x, r));
    return v;
  }

 private:
  Mesh& mesh_;
  const HeightField& h_;
  const std::vector<std::pair<std::string, HeightField>>& attributes_;
  std::array<double, 2> origin_;
  std::vector<int> index_;
};

// Rows run south in a north-up raster, north in a south-up one.
bool south_up(const HeightField& h) {
  return h.geo().geotransform[1] * h.geo().geotransform[5] > 0;
}

}  // namespace

Mesh height_field_mesh(const HeightField& h, int step,
                       const std::vector<std::pair<std::string, HeightField>>& attributes) {
  if (step < 1) throw Error("internal: height_field_mesh step " + std::to_string(step));
  require_same_grid(h, attributes);
  // The columns and rows kept: every step-th and the last.
  auto kept = [step](int n) {
    std::vector<int> k;
    for (int i = 0; i < n; i += step) k.push_back(i);
    if (k.back() != n - 1) k.push_back(n - 1);
    return k;
  };
  const std::vector<int> cols = kept(h.width()), rows = kept(h.height());
  Mesh mesh;
  GridVertices vertex(mesh, h, attributes);
  const std::size_t nc = cols.size();
  const bool flip = south_up(h);
  // At most a vertex a kept grid point and two triangles a square: reserved,
  // so the memory is what mesh_and_write_bytes counts, not up to twice it by
  // doubling.
  const std::size_t kept_points = nc * rows.size();
  mesh.positions.reserve(kept_points);
  for (auto& [name, values] : mesh.vertex_attributes) values.reserve(kept_points);
  mesh.triangles.reserve(2 * (nc - 1) * (rows.size() - 1));
  for (std::size_t j = 0; j + 1 < rows.size(); ++j) {
    for (std::size_t i = 0; i + 1 < nc; ++i) {
      const float a = h(cols[i], rows[j]), b = h(cols[i + 1], rows[j]), c = h(cols[i], rows[j + 1]),
                  d = h(cols[i + 1], rows[j + 1]);
      if (std::isnan(a) || std::isnan(b) || std::isnan(c) || std::isnan(d)) continue;
      // Rows run south in a north-up raster: (i, j+1) is south of (i, j), so
      // nw, sw, se then nw, se, ne are counter-clockwise seen from above.
      const int nw = vertex(cols[i], rows[j]), ne = vertex(cols[i + 1], rows[j]),
                sw = vertex(cols[i], rows[j + 1]), se = vertex(cols[i + 1], rows[j + 1]);
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

Mesh decimated_height_field_mesh(const HeightField& h, double max_error,
                                 const std::vector<std::pair<std::string, HeightField>>& attributes,
                                 double* measured_error, const RtinSizeCheck& before_list) {
  require_same_grid(h, attributes);
  const RtinMesh rtin = rtin_triangles(h, max_error, before_list);
  Mesh mesh;
  // Sized once: grown by doubling, the lists held up to twice the mesh.
  mesh.positions.reserve(rtin.vertices);
  mesh.triangles.reserve(rtin.triangles.size());
  GridVertices vertex(mesh, h, attributes);
  for (auto& named : mesh.vertex_attributes) named.second.reserve(rtin.vertices);
  const bool flip = south_up(h);
  for (const GridTriangle& t : rtin.triangles) {
    // Counter-clockwise from above is clockwise in (column, row) when rows
    // run south: twice the signed area in grid coordinates is negative.
    const long long cross = static_cast<long long>(t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) -
                            static_cast<long long>(t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
    const int a = vertex(t[0][0], t[0][1]), b = vertex(t[1][0], t[1][1]),
              c = vertex(t[2][0], t[2][1]);
    if ((cross < 0) != flip)
      mesh.triangles.push_back({a, b, c});
    else
      mesh.triangles.push_back({a, c, b});
  }
  if (measured_error) *measured_error = rtin.max_error;
  mesh.normals = vertex_normals(mesh);
  return mesh;
}

}  // namespace drift::terrain
