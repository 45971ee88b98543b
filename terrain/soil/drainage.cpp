#include "terrain/soil/drainage.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace drift::soil {

namespace {

// Soil below this fraction of a voxel neither passes nor holds drainage (a
// trace of falling soil is not a path for water).
constexpr float kMinSoil = 1e-4f;

}  // namespace

void drain_moisture(SoilState& s, const SoilType& soil, double dt) {
  const terrain::Grid3Shape& g = s.shape;
  const double unit = dt / (g.voxel_size * soil.porosity);  // (m/s of water) -> dw
  const float evaporate = static_cast<float>(soil.evaporation * unit);
  const double exponent = 2.0 * soil.campbell_b + 3.0;
  const bool drains = soil.drainage > 0, dries = evaporate > 0;
  if (!drains && !dries) return;
  tbb::parallel_for(0, g.ny, [&](int y) {
    std::vector<float> down(static_cast<std::size_t>(g.nz) + 1);
    for (int x = 0; x < g.nx; ++x) {
      const std::size_t c = g.column(x, y);
      float* rho = s.rho.data() + c;
      float* wet = s.wet.data() + c;
      bool any = false;
      // Moisture first: a dry column is then read in one field, not two.
      for (int z = 0; z < g.nz && !any; ++z) any = wet[z] > 0 && rho[z] > kMinSoil;
      if (!any) continue;
      // down[z]: water from voxel z into voxel z - 1, from the old state.
      std::fill(down.begin(), down.end(), 0.0f);
      if (drains)
        for (int z = 1; z < g.nz; ++z) {
          if (rho[z] <= kMinSoil || rho[z - 1] <= kMinSoil || wet[z] <= 0) continue;
          const double q = soil.drainage * std::pow(static_cast<double>(wet[z]), exponent);
          const float room = std::max(0.0f, rho[z - 1] - rho[z - 1] * wet[z - 1]);
          down[z] = std::min({static_cast<float>(q * unit), rho[z] * wet[z], room});
        }
      for (int z = 0; z < g.nz; ++z) {
        if (rho[z] <= kMinSoil) continue;
        float w = rho[z] * wet[z] - down[z] + down[z + 1];
        const bool exposed = z + 1 == g.nz || (rho[z + 1] <= kMinSoil && s.psi[c + z + 1] < 0.5f);
        if (dries && exposed) w -= std::min(std::max(0.0f, w), evaporate);
        wet[z] = std::clamp(w / rho[z], 0.0f, 1.0f);
      }
    }
  });
}

}  // namespace drift::soil
