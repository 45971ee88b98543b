#include "terrain/height_change.h"

#include <cmath>
#include <string>

#include "terrain/error.h"

namespace drift::terrain {

HeightField lay_on_ground(const HeightField& ground, const HeightField& change, const char* what) {
  if (ground.width() != change.width() || ground.height() != change.height())
    throw Error(std::string(what) + " is " + std::to_string(change.width()) + " x " +
                std::to_string(change.height()) + " cells but the ground is " +
                std::to_string(ground.width()) + " x " + std::to_string(ground.height()) +
                "; give rasters of the same grid");
  HeightField top = ground;
  for (std::size_t i = 0; i < top.size(); ++i) {
    const float d = change.values()[i];
    if (std::isfinite(d)) top.values()[i] += d;  // NaN ground stays NaN
  }
  return top;
}

}  // namespace drift::terrain
