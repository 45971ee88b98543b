// The temporary files a run has open, kept where the signal cleanup can reach
// them: every signal whose default action ends the process and that comes from
// outside it (SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM,
// SIGPIPE, SIGXFSZ, SIGXCPU, SIGVTALRM, SIGPROF, SIGIO, SIGPWR, SIGSTKFLT)
// removes every one of them, prints one line and exits 128 + the signal (130,
// 143, 129, ...), so an interrupted run leaves no temporary file and every
// existing output as it was.
#pragma once

#include <filesystem>

namespace drift {

// Blocks those signals in the calling thread (and so in every
// thread it starts later) and starts one thread that waits for them and does the
// cleanup (once; the program calls it at start, before any other thread exists).
// A handler run on whichever thread the kernel picks could not stop the other
// threads from creating or renaming a file while it cleans up; one waiting
// thread that takes the DeferSignals lock can. Without this call, temporary
// files are still removed on every error, but a signal kills the process with
// the default action.
void install_signal_cleanup();

// Records `temp` for removal on a signal; returns its slot. Throws drift::Error
// if the path is too long or too many temporary files are open at once.
int register_temp(const std::filesystem::path& temp);

// Forgets a slot (the file was renamed into place or removed).
void forget_temp(int slot);

// Test hooks, inert unless the environment asks. Points where a run can be
// stopped so that a test can send a signal at exactly that moment:
//   DRIFT_TEST_STOP_AT_WRITE=N     as the N-th output starts to be written,
//   DRIFT_TEST_STOP_AT_PROGRESS=N  at the N-th progress report of the computation.
// There the process stops itself (SIGSTOP) and the test continues it (SIGCONT).
// With DRIFT_TEST_AWAIT_SIGNAL=1 it then waits for the signal the test sent
// before continuing it, so the run cannot go on racing the cleanup.
enum class TestPoint { write, progress };
void stop_here_for_tests(TestPoint point = TestPoint::write);
// Whether the environment asks to stop at `point` (callers skip wrapping otherwise).
bool stop_wanted_for_tests(TestPoint point);

// While alive, the signal cleanup waits: creating and recording a temporary
// file, or renaming a run's outputs into place, finishes before a signal takes
// effect, so outputs are replaced all together or not at all. Nests.
class DeferSignals {
 public:
  // `renaming`: outputs are being moved into place (the message says so if a
  // signal came meanwhile).
  explicit DeferSignals(bool renaming = false);
  ~DeferSignals();
  DeferSignals(const DeferSignals&) = delete;
  DeferSignals& operator=(const DeferSignals&) = delete;
};

}  // namespace drift
