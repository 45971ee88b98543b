#include "snow/snowfall_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "snow/snowfall_mesh_refine.h"
#include "terrain/error.h"

namespace drift::snow {

Eigen::Vector3d SnowScene::ground_normal(int col, int row) const {
  const int xl = std::max(col - 1, 0), xr = std::min(col + 1, ground.width() - 1);
  const int rn = std::max(row - 1, 0), rs = std::min(row + 1, ground.height() - 1);
  const double dzdx = (ground(xr, row) - ground(xl, row)) / ((xr - xl) * dx);
  const double dzdy = (ground(col, rn) - ground(col, rs)) / ((rs - rn) * dy);
  return Eigen::Vector3d(-dzdx, -dzdy, 1.0).normalized();
}

SnowScene make_snow_scene(const terrain::HeightField& ground,
                          const std::vector<SnowObject>& objects, double max_edge) {
  const auto& geo = ground.geo();
  if (!geo.north_up() || geo.cell_size_x() <= 0 || geo.cell_size_y() <= 0) {
    throw Error(
        "the ground raster must be north-up with positive cell sizes in metres "
        "(run drift import on it first)");
  }
  if (ground.width() < 2 || ground.height() < 2) {
    throw Error("the ground raster must be at least 2 x 2 cells");
  }
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (float v : ground.values())
    if (!std::isnan(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!std::isfinite(lo)) throw Error("the ground raster holds no valid height (all nodata)");

  SnowScene s;
  s.dx = geo.cell_size_x();
  s.dy = geo.cell_size_y();
  const auto centre = geo.cell_center((ground.width() - 1) / 2.0, (ground.height() - 1) / 2.0);
  s.origin = Eigen::Vector3d(centre[0], centre[1], lo);
  const auto nw = geo.cell_center(0, 0);
  s.x0 = nw[0] - s.origin.x();
  s.y0 = nw[1] - s.origin.y();
  s.ground = terrain::Grid<float>(ground.width(), ground.height(), 0.0f, geo);
  for (std::size_t i = 0; i < ground.size(); ++i) {
    const float v = ground.values()[i];
    s.ground.values()[i] = (std::isnan(v) ? lo : v) - lo;
  }
  s.ground_lo = 0.0f;
  s.ground_hi = hi - lo;
  for (const SnowObject& object : objects) {
    terrain::Mesh local;
    local.triangles = object.mesh.triangles;
    local.positions.reserve(object.mesh.positions.size());
    const Eigen::Vector3d shift = object.position - s.origin;
    for (const auto& p : object.mesh.positions)
      local.positions.push_back((p.cast<double>() + shift).cast<float>());
    s.meshes.push_back(refine_mesh(local, max_edge));
  }
  return s;
}

}  // namespace drift::snow
