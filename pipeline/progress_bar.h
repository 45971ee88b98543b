// A terminal progress bar with elapsed time and time left, drawn on stderr only
// when stderr is a terminal (quiet in pipes, make logs and CI).
#pragma once

#include <string>

#include "terrain/progress.h"

namespace drift::pipeline {

// Returns a thread-safe ProgressFn labelled `label`; never cancels.
ProgressFn terminal_progress(const std::string& label);

}  // namespace drift::pipeline
