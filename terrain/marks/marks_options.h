// The marks stage's options. Their ranges, flags and keys live in one table,
// terrain/marks/marks_parameters.h.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "terrain/marks/object_bottom.h"

namespace drift::marks {

// A camera to choose resolutions by (paper 000, 3.6 A): a cell projects to
// about cell x focal / distance pixels.
struct MarksCamera {
  Eigen::Vector3d position{0, 0, 0};
  double fov_deg = 40.0;  // horizontal
  int width_px = 1280;
};

struct MarksOptions {
  double step = 0.1;
  int memory_steps = 20;
  int erosion_passes = 100;
  int margin = 4;
  BottomRenderer renderer = BottomRenderer::Cpu;
  std::uint64_t seed = 0;
  std::optional<MarksCamera> camera;
  bool track_disturbed = true;  // keep the per-cell disturbance raster
  // The ground is a window of a larger raster (marks block by block,
  // terrain/marks/marks_blocks.h): where it starts in that raster's cells,
  // the raster's width and first cell centre. Objects are placed and the
  // roughness drawn as on the whole raster.
  struct Window {
    int col0 = 0, row0 = 0;
    std::int64_t raster_width = 0;
    double x0 = 0.0, y0 = 0.0;  // the raster's first cell centre (m)
  };
  std::optional<Window> window;
  // Throws drift::Error naming the option.
  void validate() const;
};

}  // namespace drift::marks
