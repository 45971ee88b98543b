// A planted folder for the include-layer check's own test (tests/CMakeLists.txt,
// include_layers_catches_a_new_folder): a module the build does not know, which
// includes two stages. The old hand-written check passed this tree.
#pragma once
#include "dunes/sand_model.h"
#include "render/renderer.h"
