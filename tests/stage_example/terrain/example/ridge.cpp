#include "terrain/example/ridge.h"

#include <algorithm>
#include <cmath>

namespace drift::example {

terrain::HeightField ridge(int size, double height_m) {
  terrain::HeightField field(size, size, 0.0f);
  for (int row = 0; row < size; ++row) {
    const double from_middle = std::abs(row - 0.5 * (size - 1)) / (0.5 * size);
    for (int x = 0; x < size; ++x)
      field(x, row) = static_cast<float>(height_m * std::max(0.0, 1.0 - from_middle));
  }
  return field;
}

}  // namespace drift::example
