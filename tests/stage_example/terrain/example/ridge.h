// The example stage's one product: a ridge across a square field.
#pragma once

#include "terrain/grid.h"

namespace drift::example {

// `size` x `size` cells, a ridge `height_m` high along the middle row.
terrain::HeightField ridge(int size, double height_m);

}  // namespace drift::example
