// See lens.h.
#pragma once
