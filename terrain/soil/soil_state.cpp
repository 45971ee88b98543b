#include "terrain/soil/soil_state.h"

#include "terrain/memory.h"

namespace drift::soil {

// 9 fields in the state, 8 back buffers for the passes, one byte the settle's walks mark.
std::uint64_t soil_state_bytes(const terrain::Grid3Shape& shape) {
  return static_cast<std::uint64_t>(shape.count()) * (17 * sizeof(float) + 1);
}

SoilState::SoilState(const terrain::Grid3Shape& s) : shape(s) {
  if (s.nx <= 0 || s.ny <= 0 || s.nz <= 0)
    throw Error("soil grid size must be positive, got " + std::to_string(s.nx) + " x " +
                std::to_string(s.ny) + " x " + std::to_string(s.nz));
  if (s.nz > 32000)
    throw Error("soil grid is " + std::to_string(s.nz) + " voxels tall; at most 32000");
  require_memory(soil_state_bytes(s),
                 "soil grid " + std::to_string(s.nx) + " x " + std::to_string(s.ny) + " x " +
                     std::to_string(s.nz),
                 "use a smaller grid or larger voxels");
  const std::size_t n = s.count();
  for (auto* f : {&rho, &ux, &uy, &uz, &fx, &fy, &fz, &psi, &psi_static, &back.rho, &back.ux,
                  &back.uy, &back.uz, &back.fx, &back.fy, &back.fz, &back.moving})
    f->assign(n, 0.0f);
  back.visited.assign(n, 0);
}

void SoilState::swap_back() {
  rho.swap(back.rho);
  ux.swap(back.ux);
  uy.swap(back.uy);
  uz.swap(back.uz);
  fx.swap(back.fx);
  fy.swap(back.fy);
  fz.swap(back.fz);
}

double SoilState::mass() const {
  // Column by column, so the order never depends on anything but the grid.
  double total = 0.0;
  for (std::size_t c = 0; c < shape.columns(); ++c) {
    double column = 0.0;
    const float* r = rho.data() + c * shape.nz;
    for (int z = 0; z < shape.nz; ++z) column += r[z];
    total += column;
  }
  return total;
}

}  // namespace drift::soil
