// The temporary files a run has open, kept where a signal handler can reach
// them: SIGINT, SIGTERM and SIGHUP remove every one of them, print one line and
// exit 130, 143 or 129 (128 + the signal), so an interrupted run leaves no
// temporary file and every existing output as it was.
#pragma once

#include <filesystem>

namespace drift {

// Installs the handlers for SIGINT, SIGTERM and SIGHUP (once; the program calls
// it at start). Without it, temporary files are still removed on every error,
// but a signal kills the process with the default action.
void install_signal_cleanup();

// Records `temp` for removal on a signal; returns its slot. Throws drift::Error
// if the path is too long or too many temporary files are open at once.
int register_temp(const std::filesystem::path& temp);

// Forgets a slot (the file was renamed into place or removed).
void forget_temp(int slot);

// Test hook: when the environment sets DRIFT_TEST_STOP_AT_WRITE=N, the process
// stops itself (SIGSTOP) as the N-th output starts to be written, so that a test
// can send a signal at exactly that point and then continue it. Unset: nothing.
void stop_here_for_tests();

// While alive, a signal is only noted; when the last DeferSignals ends it is
// acted on. Renaming a run's outputs into place thus finishes before a signal
// takes effect, so outputs are replaced all together or not at all. (Blocking
// the signals would not do: any of TBB's threads may receive them.)
class DeferSignals {
 public:
  // `renaming`: outputs are being moved into place (says so if a signal came).
  explicit DeferSignals(bool renaming = false);
  ~DeferSignals();
  DeferSignals(const DeferSignals&) = delete;
  DeferSignals& operator=(const DeferSignals&) = delete;

 private:
  bool renaming_;
};

}  // namespace drift
