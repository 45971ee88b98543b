// Two components of one folder that include each other (a header and the other's
// source), as render/path_tracer.h and render/renderer.cpp once did: the check
// must name the loop (tests/CMakeLists.txt, include_layers_catches_a_loop).
#pragma once
#include "render/shutter.h"
