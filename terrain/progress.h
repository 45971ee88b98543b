// Progress reporting for long-running library calls, in the manner of GDAL's
// GDALProgressFunc: fraction in [0, 1] (0 reported first, 1 last), a short
// message, and a return value of false to cancel.
#pragma once

#include <functional>
#include <string_view>

namespace drift {

using ProgressFn = std::function<bool(double fraction, std::string_view message)>;

// Reports nothing and never cancels.
inline bool no_progress(double, std::string_view) { return true; }

// Maps [0, 1] of a sub-step onto [begin, end] of the parent's range, so multi-step
// work reports one monotone bar (like GDALCreateScaledProgress).
inline ProgressFn scaled_progress(const ProgressFn& parent, double begin, double end) {
  if (!parent) return no_progress;
  return [parent, begin, end](double f, std::string_view msg) {
    return parent(begin + (end - begin) * f, msg);
  };
}

}  // namespace drift
