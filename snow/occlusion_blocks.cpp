#include "snow/occlusion_blocks.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "terrain/error.h"

namespace drift::snow {

int occlusion_halo_cells(const SnowScene& scene, const std::vector<FallDirection>& dirs) {
  const double relief = static_cast<double>(scene.ground_hi) - scene.ground_lo;
  int halo = 0;
  for (const FallDirection& d : dirs) {
    const Eigen::Vector3d& w = d.toward_source;
    const double horizontal = std::hypot(w.x(), w.y());
    if (horizontal < 1e-9) continue;  // straight down: S = the heights
    // As in HorizonSweeper::shadow: the metres between lines along the ray.
    const double dcol = std::abs(w.x()) / horizontal / scene.dx;
    const double drow = std::abs(w.y()) / horizontal / scene.dy;
    const double metres = 1.0 / std::max(dcol, drow);
    const double drop = metres * w.z() / horizontal;
    const double lines = std::ceil(relief / drop) + 1.0;
    halo = std::max(halo, static_cast<int>(std::min(2.0 * lines + 2.0, 1e9)));
  }
  return halo + 1;  // + 1: the central differences of the normals
}

SnowProbability ground_probability_in_blocks(const SnowScene& scene,
                                             const std::vector<FallDirection>& dirs, int block,
                                             const ProbabilityOptions& options) {
  if (!scene.meshes.empty() || options.terrain != TerrainOcclusion::Sweep)
    throw Error("the snow probability block by block takes the ground alone, by the sweep");
  if (block < 1) throw Error("the snow probability's block must be 1 cell or more");
  const int W = scene.ground.width(), H = scene.ground.height();
  const int halo = occlusion_halo_cells(scene, dirs);
  // A block past the grid is the grid (the same bits): near INT_MAX, bx +
  // block + halo overflowed and a negative size aborted (--block 2147483647).
  block = std::min(block, std::max(W, H));
  SnowProbability out;
  out.ground = terrain::Grid<float>(W, H, 0.0f);
  out.ground_facing = terrain::Grid<float>(W, H, 0.0f);
  for (int by = 0; by < H; by += block)
    for (int bx = 0; bx < W; bx += block) {
      const int c0 = std::max(0, bx - halo), r0 = std::max(0, by - halo);
      const int c1 = static_cast<int>(std::min<std::int64_t>(W, std::int64_t{bx} + block + halo));
      const int r1 = static_cast<int>(std::min<std::int64_t>(H, std::int64_t{by} + block + halo));
      SnowScene part;
      part.ground = terrain::Grid<float>(c1 - c0, r1 - r0);
      for (int r = r0; r < r1; ++r)
        std::copy_n(&scene.ground(c0, r), c1 - c0, &part.ground(0, r - r0));
      part.x0 = scene.x0 + c0 * scene.dx;
      part.y0 = scene.y0 - r0 * scene.dy;
      part.dx = scene.dx, part.dy = scene.dy;
      part.origin = scene.origin;
      part.ground_lo = scene.ground_lo, part.ground_hi = scene.ground_hi;
      const SnowProbability p = snow_probability(part, dirs, options);
      for (int r = by; r < std::min(H, by + block); ++r)
        for (int c = bx; c < std::min(W, bx + block); ++c) {
          out.ground(c, r) = p.ground(c - c0, r - r0);
          out.ground_facing(c, r) = p.ground_facing(c - c0, r - r0);
        }
    }
  return out;
}

}  // namespace drift::snow
