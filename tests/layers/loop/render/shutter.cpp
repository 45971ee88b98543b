// See lens.h.
#include "render/shutter.h"
#include "render/lens.h"
