#include "pipeline/progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>

#include "terrain/temp_registry.h"

namespace drift::pipeline {

namespace {

struct BarState {
  std::string label;
  std::mutex mutex;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_draw{};
  double last_fraction = -1.0;
};

std::string format_seconds(double s) {
  char buf[32];
  const long t = std::lround(s);
  if (t >= 3600) {
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t / 60) % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  }
  return buf;
}

ProgressFn draw_bar(const std::string& label) {
  if (!isatty(STDERR_FILENO)) return no_progress;
  auto state = std::make_shared<BarState>();
  state->label = label;
  return [state](double fraction, std::string_view message) {
    fraction = std::clamp(fraction, 0.0, 1.0);
    std::lock_guard lock(state->mutex);
    const auto now = std::chrono::steady_clock::now();
    const bool done = fraction >= 1.0;
    // Redraw at most 10 times a second, and always at the end.
    if (!done && now - state->last_draw < std::chrono::milliseconds(100)) return true;
    if (done && state->last_fraction >= 1.0) return true;
    state->last_draw = now;
    state->last_fraction = fraction;
    const double elapsed = std::chrono::duration<double>(now - state->start).count();
    const int width = 30;
    const int filled = static_cast<int>(fraction * width);
    std::string bar(filled, '#');
    bar.resize(width, '.');
    std::string eta = "--";
    if (fraction > 0.01) eta = format_seconds(elapsed * (1.0 - fraction) / fraction);
    std::fprintf(stderr, "\r%s [%s] %3d%% %s elapsed, %s left %.*s\033[K", state->label.c_str(),
                 bar.c_str(), static_cast<int>(fraction * 100.0), format_seconds(elapsed).c_str(),
                 eta.c_str(), static_cast<int>(message.size()), message.data());
    if (done) std::fputc('\n', stderr);
    std::fflush(stderr);
    return true;
  };
}

}  // namespace

ProgressFn terminal_progress(const std::string& label) {
  ProgressFn bar = draw_bar(label);
  if (!stop_wanted_for_tests(TestPoint::progress)) return bar;
  // Test hook (terrain/temp_registry.h): a stop point during the computation.
  return [bar](double fraction, std::string_view message) {
    stop_here_for_tests(TestPoint::progress);
    return bar(fraction, message);
  };
}

}  // namespace drift::pipeline
