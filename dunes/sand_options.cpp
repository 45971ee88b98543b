#include "dunes/sand_options.h"

namespace drift::dunes {

SandOptions default_options(Model model) {
  if (model != Model::Dunes) return {.model = model};
  // Large scale: flights shorten and lift grows on windward slopes.
  return {.model = model,
          .cell_m = 1.0,
          .height_unit = 0.25,
          .steps = 3000,
          .L0 = 20.0,
          .b = 1.0,
          .q = 0.2,
          .b_prime = 0.02,
          .creep = 0.25,
          .initial_amplitude = 2.0,
          .shadow_deg = 15.0,
          .reattach = 1.0};
}

}  // namespace drift::dunes
