#include "dunes/sand_options.h"

namespace drift::dunes {

SandOptions default_options(Model model) {
  SandOptions o;
  o.model = model;
  if (model == Model::Dunes) {
    // Large scale: flights shorten and lift grows on windward slopes.
    o.cell_m = 1.0;
    o.height_unit = 0.25;
    o.L0 = 20.0;
    o.b = 1.0;
    o.q = 0.2;
    o.b_prime = 0.02;
    o.creep = 0.25;
    o.initial_amplitude = 2.0;
    o.steps = 3000;
    o.shadow_deg = 15.0;
    o.reattach = 1.0;
  }
  return o;
}

}  // namespace drift::dunes
