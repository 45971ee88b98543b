// A stage including the planted folder (tests/layers/planted/ice).
#include "ice/ice_sheet.h"
#include "terrain/grid.h"
