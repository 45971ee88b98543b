#include "snow/snowfall_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "snow/snowfall_mesh_refine.h"
#include "terrain/derivatives.h"
#include "terrain/error.h"
#include "terrain/local_frame.h"

namespace drift::snow {

Eigen::Vector2d SnowScene::ground_gradient(int col, int row) const {
  return terrain::central_gradient(ground, ground.width(), ground.height(), dx, dy, col, row);
}

Eigen::Vector3d SnowScene::ground_normal(int col, int row) const {
  return terrain::normal_from_gradient(ground_gradient(col, row));
}

SnowScene make_snow_scene(const terrain::HeightField& ground,
                          const std::vector<terrain::PlacedMesh>& objects, double max_edge) {
  const auto& geo = ground.geo();
  if (!geo.north_up() || geo.cell_size_x() <= 0 || geo.cell_size_y() <= 0) {
    throw Error(
        "the ground raster must be north-up with positive cell sizes in metres "
        "(run drift import on it first)");
  }
  if (ground.width() < 2 || ground.height() < 2) {
    throw Error("the ground raster must be at least 2 x 2 cells");
  }
  const terrain::LocalFrame frame = terrain::local_frame(ground, "the ground raster");
  const float lo = frame.lowest, hi = frame.highest;

  SnowScene s;
  s.dx = geo.cell_size_x();
  s.dy = geo.cell_size_y();
  s.origin = frame.origin;
  s.x0 = frame.x0;
  s.y0 = frame.y0;
  s.ground = terrain::Grid<float>(ground.width(), ground.height(), 0.0f, geo);
  for (std::size_t i = 0; i < ground.size(); ++i) {
    const float v = ground.values()[i];
    s.ground.values()[i] = (std::isnan(v) ? lo : v) - lo;
  }
  s.ground_lo = 0.0f;
  s.ground_hi = hi - lo;
  for (const terrain::PlacedMesh& object : objects) {
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
