// A deliberate layer violation for the include-layer check's own test
// (tests/CMakeLists.txt, include_layers_catches): a stage including another
// stage. Never compiled.
#include "dunes/sand_model.h"
#include "terrain/grid.h"
