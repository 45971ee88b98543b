// The object's bottom rendered by OSMesa (paper 000, 3.3: OpenGL looking up
// from below the ground, orthographic, one pixel per cell), through the depth
// renderer shared with snowfall (terrain/offscreen). Depths are 32-bit floats
// measured from the object's lowest point, so they keep sub-millimetre
// precision whatever the ground's altitude.
#pragma once

#include <memory>

#include "terrain/marks/object_bottom.h"

namespace drift::marks {

// Throws drift::Error if OSMesa cannot make a context. Use on one thread.
std::unique_ptr<BottomRasteriser> make_osmesa_bottom_rasteriser();

}  // namespace drift::marks
