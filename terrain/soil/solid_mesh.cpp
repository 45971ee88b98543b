#include "terrain/soil/solid_mesh.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "terrain/error.h"

namespace drift::soil {

SolidMesh::SolidMesh(const terrain::Mesh& mesh, double cell, const std::string& name)
    : cell_(cell) {
  if (mesh.positions.empty() || mesh.triangles.empty())
    throw Error("body '" + name + "': its mesh has no triangles");
  if (!(std::isfinite(cell) && cell > 0))
    throw Error("body '" + name + "': mesh cell must be a positive number of metres");
  lo_ = Eigen::Vector3d::Constant(1e300);
  hi_ = Eigen::Vector3d::Constant(-1e300);
  for (const Eigen::Vector3f& p : mesh.positions) {
    if (!p.allFinite()) throw Error("body '" + name + "': its mesh has a non-finite vertex");
    lo_ = lo_.cwiseMin(p.cast<double>());
    hi_ = hi_.cwiseMax(p.cast<double>());
  }
  std::uint64_t cells = 1;
  for (int a = 0; a < 3; ++a) {
    n_[a] = std::max(1, static_cast<int>(std::ceil((hi_[a] - lo_[a]) / cell)));
    cells *= static_cast<std::uint64_t>(n_[a]);
  }
  if (cells > kMaxCells)
    throw Error("body '" + name + "': its mesh spans " + std::to_string(n_[0]) + " x " +
                std::to_string(n_[1]) + " x " + std::to_string(n_[2]) +
                " cells of half a voxel; scale the mesh down or use larger voxels");
  solid_.assign(cells, 0);
  // Per column (x, y) of the body's grid, the heights where a vertical line
  // through the column's centre crosses a triangle; between the 1st and 2nd,
  // 3rd and 4th, ... crossing lies the solid. The line is nudged off the
  // cell centre by an irrational fraction so it never runs along an edge.
  const double nudge_x = 1e-4 * std::sqrt(2.0) * cell, nudge_y = 1e-4 * std::sqrt(3.0) * cell;
  std::vector<std::vector<int>> bins(static_cast<std::size_t>(n_[0]) * n_[1]);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& p = mesh.positions[tri[k]];
      x0 = std::min<double>(x0, p.x()), x1 = std::max<double>(x1, p.x());
      y0 = std::min<double>(y0, p.y()), y1 = std::max<double>(y1, p.y());
    }
    const int i0 = std::max(0, static_cast<int>(std::floor((x0 - lo_.x()) / cell - 0.5)));
    const int i1 = std::min(n_[0] - 1, static_cast<int>(std::ceil((x1 - lo_.x()) / cell - 0.5)));
    const int j0 = std::max(0, static_cast<int>(std::floor((y0 - lo_.y()) / cell - 0.5)));
    const int j1 = std::min(n_[1] - 1, static_cast<int>(std::ceil((y1 - lo_.y()) / cell - 0.5)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i)
        bins[static_cast<std::size_t>(j) * n_[0] + i].push_back(static_cast<int>(t));
  }
  tbb::parallel_for(0, n_[1], [&](int j) {
    std::vector<double> hits;
    for (int i = 0; i < n_[0]; ++i) {
      const double px = lo_.x() + (i + 0.5) * cell + nudge_x;
      const double py = lo_.y() + (j + 0.5) * cell + nudge_y;
      hits.clear();
      for (int t : bins[static_cast<std::size_t>(j) * n_[0] + i]) {
        const auto& tri = mesh.triangles[t];
        const Eigen::Vector3d a = mesh.positions[tri[0]].cast<double>(),
                              b = mesh.positions[tri[1]].cast<double>(),
                              c = mesh.positions[tri[2]].cast<double>();
        // Barycentric coordinates of (px, py) in the triangle's xy projection.
        const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
        if (det == 0) continue;  // seen edge-on from above
        const double u = ((px - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (py - a.y())) / det;
        const double v = ((b.x() - a.x()) * (py - a.y()) - (px - a.x()) * (b.y() - a.y())) / det;
        if (u < 0 || v < 0 || u + v > 1) continue;
        hits.push_back(a.z() + u * (b.z() - a.z()) + v * (c.z() - a.z()));
      }
      std::sort(hits.begin(), hits.end());
      for (std::size_t h = 0; h + 1 < hits.size(); h += 2)
        for (int k = 0; k < n_[2]; ++k) {
          const double z = lo_.z() + (k + 0.5) * cell;
          if (z >= hits[h] && z < hits[h + 1])
            solid_[(static_cast<std::size_t>(k) * n_[1] + j) * n_[0] + i] = 1;
        }
    }
  });
  for (std::uint8_t s : solid_) solid_cells_ += s;
  if (solid_cells_ == 0)
    throw Error("body '" + name +
                "': its mesh encloses no solid at half a voxel; it must be a closed surface "
                "thicker than half a voxel");
}

bool SolidMesh::inside(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d q = (p - lo_) / cell_;
  const int i = static_cast<int>(std::floor(q.x())), j = static_cast<int>(std::floor(q.y())),
            k = static_cast<int>(std::floor(q.z()));
  if (i < 0 || j < 0 || k < 0 || i >= n_[0] || j >= n_[1] || k >= n_[2]) return false;
  return solid_[(static_cast<std::size_t>(k) * n_[1] + j) * n_[0] + i] != 0;
}

}  // namespace drift::soil

namespace drift::soil {

int SolidMesh::classify(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) const {
  int a[3], b[3];
  bool outside_grid = false;
  for (int d = 0; d < 3; ++d) {
    a[d] = static_cast<int>(std::floor((lo[d] - lo_[d]) / cell_));
    b[d] = static_cast<int>(std::floor((hi[d] - lo_[d]) / cell_));
    if (b[d] < 0 || a[d] >= n_[d]) return 0;
    if (a[d] < 0 || b[d] >= n_[d]) outside_grid = true;  // part of the box lies off the grid
    a[d] = std::max(a[d], 0);
    b[d] = std::min(b[d], n_[d] - 1);
  }
  bool any = false, all = !outside_grid;
  for (int k = a[2]; k <= b[2]; ++k)
    for (int j = a[1]; j <= b[1]; ++j)
      for (int i = a[0]; i <= b[0]; ++i) {
        const bool s = solid_[(static_cast<std::size_t>(k) * n_[1] + j) * n_[0] + i] != 0;
        any = any || s;
        all = all && s;
        if (any && !all) return -1;
      }
  return all ? 1 : any ? -1 : 0;
}

}  // namespace drift::soil
