#include "dunes/sand_parameters.h"

#include <cstring>

namespace drift::dunes {

bool dunes_only(const terrain::Parameter<SandOptions>& p) {
  return std::strcmp(p.field, "b_prime") == 0;
}

}  // namespace drift::dunes
