// The object's bottom rendered by OSMesa (paper 000, 3.3: OpenGL looking up
// from below the ground, orthographic, one pixel per cell), through the depth
// renderer shared with snowfall (terrain/offscreen). Depths are 32-bit floats
// measured from the object's lowest point, so they keep sub-millimetre
// precision whatever the ground's altitude.
#include <algorithm>

#include "terrain/marks/object_bottom.h"
#include "terrain/mesh.h"
#include "terrain/offscreen/depth_map.h"
#include "terrain/offscreen/osmesa_depth_renderer.h"

namespace drift::marks {

namespace {

class OsmesaBottomRasteriser final : public BottomRasteriser {
 private:
  void lower(const CellTriangles& tris, BottomMap& map) override {
    const CellWindow& w = map.window;
    if (tris.empty() || w.empty()) return;
    double z_lo = 1e300, z_hi = -1e300;
    for (const Eigen::Vector3d& p : tris)
      z_lo = std::min(z_lo, p.z()), z_hi = std::max(z_hi, p.z());
    // Looking up: the source is below, w = -z, so a = column and b = -y; the
    // mesh is given in (column, -row, z - z_lo) so that b runs with the rows.
    mesh_.positions.resize(tris.size());
    mesh_.triangles.resize(tris.size() / 3);
    for (std::size_t i = 0; i < tris.size(); ++i)
      mesh_.positions[i] =
          Eigen::Vector3f(static_cast<float>(tris[i].x()), static_cast<float>(-tris[i].y()),
                          static_cast<float>(tris[i].z() - z_lo));
    for (std::size_t t = 0; t < mesh_.triangles.size(); ++t)
      mesh_.triangles[t] = {static_cast<int>(3 * t), static_cast<int>(3 * t + 1),
                            static_cast<int>(3 * t + 2)};
    terrain::DepthMap depth;
    depth.frame = terrain::LightFrame::toward(-Eigen::Vector3d::UnitZ());
    depth.texel = 1.0;
    depth.a0 = w.col0 - 0.5;  // pixel centres on cell centres
    depth.b0 = w.row0 - 0.5;
    depth.width = w.width;
    depth.height = w.height;
    renderer_.render(depth, -(z_hi - z_lo), 0.0, {&mesh_}, nullptr);
    for (std::size_t i = 0; i < map.z.size(); ++i) {
      const float top = depth.top[i];  // largest c = -z, relative to c_ref
      if (top != terrain::DepthMap::kEmpty)
        map.z[i] = z_lo - (static_cast<double>(top) + depth.c_ref);
    }
  }

  terrain::OsmesaDepthRenderer renderer_;
  terrain::Mesh mesh_;
};

}  // namespace

std::unique_ptr<BottomRasteriser> make_osmesa_bottom_rasteriser() {
  return std::make_unique<OsmesaBottomRasteriser>();
}

}  // namespace drift::marks
