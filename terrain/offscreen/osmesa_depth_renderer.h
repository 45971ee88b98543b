// Depth maps rendered off-screen with OSMesa (Mesa's llvmpipe), as the papers
// used graphics hardware for shadow maps (paper 003, 2.1(1)) and collisions
// (paper 000, 3.3). A 32-bit float depth attachment (GL_DEPTH_COMPONENT32F)
// keeps the depth precise over kilometres of relief; maps larger than a tile
// are drawn tile by tile.
//
// One renderer owns one OSMesa context, current on the thread that made it:
// create, use and destroy it on one thread.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "terrain/grid.h"
#include "terrain/mesh.h"
#include "terrain/offscreen/depth_map.h"

namespace drift::terrain {

// A height field as triangles: vertex (col, row) stands at
// (x0 + col * dx, y0 - row * dy, heights(col, row)) in the local frame.
struct GroundGeometry {
  const Grid<float>* heights = nullptr;
  double x0 = 0, y0 = 0, dx = 1, dy = 1;
};

class OsmesaDepthRenderer {
 public:
  OsmesaDepthRenderer();  // throws drift::Error if OSMesa cannot make a context
  ~OsmesaDepthRenderer();
  OsmesaDepthRenderer(const OsmesaDepthRenderer&) = delete;
  OsmesaDepthRenderer& operator=(const OsmesaDepthRenderer&) = delete;

  // Fills map.top for the map's frame, corner, texel and size (set by the caller)
  // with the nearest surface among `meshes` (positions in the local frame) and
  // `ground` (may be null). [c_lo, c_hi] must enclose the geometry's depths.
  void render(DepthMap& map, double c_lo, double c_hi, const std::vector<const Mesh*>& meshes,
              const GroundGeometry* ground);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drift::terrain
