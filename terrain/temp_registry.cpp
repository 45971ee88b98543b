#include "terrain/temp_registry.h"

#include <limits.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <thread>

#include "terrain/error.h"

namespace drift {

namespace {

// A fixed table, no allocation: the cleanup runs while other threads may be in
// the middle of anything, so it only reads plain memory and calls unlink,
// write and _exit.
constexpr int kSlots = 64;
enum : int { kFree = 0, kFilling = 1, kLive = 2 };
struct Slot {
  std::atomic<int> state{kFree};
  char path[PATH_MAX];
};
Slot g_slots[kSlots];
// Held by DeferSignals; the cleanup takes it before touching any file.
std::recursive_mutex g_defer;
std::atomic<unsigned> g_renames{0};  // how many renamings have begun
static_assert(std::atomic<int>::is_always_lock_free, "the cleanup reads these without a lock");

void write_text(const char* s) {
  const ssize_t ignored = write(STDERR_FILENO, s, std::strlen(s));
  (void)ignored;
}

// Every signal whose default action ends the process and that can come from
// outside it (kill, the terminal, a timer, a resource limit), with its name.
// The synchronous ones (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, ...) mean a
// bug and are left to their default action and the sanitizers. SIGPIPE and
// SIGXFSZ raised by a write of ours stay pending on the writing thread, blocked
// as they are: the write fails with EPIPE or EFBIG instead, and the writer's
// error path removes the temporary file and exits 1 with a message.
struct FatalSignal {
  int number;
  const char* name;
};
constexpr FatalSignal kFatalSignals[] = {
    {SIGINT, "SIGINT"},   {SIGTERM, "SIGTERM"}, {SIGHUP, "SIGHUP"},       {SIGQUIT, "SIGQUIT"},
    {SIGUSR1, "SIGUSR1"}, {SIGUSR2, "SIGUSR2"}, {SIGALRM, "SIGALRM"},     {SIGPIPE, "SIGPIPE"},
    {SIGXFSZ, "SIGXFSZ"}, {SIGXCPU, "SIGXCPU"}, {SIGVTALRM, "SIGVTALRM"}, {SIGPROF, "SIGPROF"},
    {SIGIO, "SIGIO"},     {SIGPWR, "SIGPWR"},   {SIGSTKFLT, "SIGSTKFLT"},
};

const char* signal_name(int sig) {
  for (const FatalSignal& s : kFatalSignals) {
    if (s.number == sig) return s.name;
  }
  return "a signal";
}

// Removes every live temporary file, says so in one line and exits 128 + sig.
[[noreturn]] void clean_up_and_exit(int sig, const char* outcome) {
  for (Slot& slot : g_slots) {
    if (slot.state.load(std::memory_order_acquire) == kLive) unlink(slot.path);
  }
  write_text("drift: interrupted by ");
  write_text(signal_name(sig));
  write_text(outcome);
  _exit(128 + sig);
}

sigset_t cleanup_signals() {
  sigset_t set;
  sigemptyset(&set);
  for (const FatalSignal& s : kFatalSignals) sigaddset(&set, s.number);
  return set;
}

// The one thread that receives the signals (all others block them). It waits
// for any creation or renaming in progress (the DeferSignals lock), then cleans
// up while holding the lock, so no thread can create or rename a file meanwhile.
void await_signals(sigset_t set) {
  int sig = 0;
  while (sigwait(&set, &sig) != 0) {
  }
  // A renaming under way when the signal came has finished once the lock is
  // ours. Any renaming at all means some outputs are already in place (a run's
  // set, frames, snapshots), and the message must not claim otherwise.
  g_defer.lock();
  clean_up_and_exit(sig, g_renames.load() > 0
                             ? "; outputs already moved into place are complete, temporary files "
                               "removed, any other existing outputs left as they were\n"
                             : "; temporary files removed, existing outputs left as they were\n");
}

int wanted_count(TestPoint point) {
  static const char* write = std::getenv("DRIFT_TEST_STOP_AT_WRITE");
  static const char* progress = std::getenv("DRIFT_TEST_STOP_AT_PROGRESS");
  const char* wanted = point == TestPoint::write ? write : progress;
  return wanted ? std::atoi(wanted) : 0;
}

}  // namespace

void install_signal_cleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    const sigset_t set = cleanup_signals();
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    std::thread(await_signals, set).detach();
  });
}

int register_temp(const std::filesystem::path& temp) {
  const std::string& s = temp.native();
  if (s.size() >= PATH_MAX) {
    throw Error("temporary file name for '" + s + "' is longer than the system's path limit (" +
                std::to_string(PATH_MAX) + "); use a shorter output path");
  }
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (g_slots[i].state.compare_exchange_strong(expected, kFilling)) {
      std::memcpy(g_slots[i].path, s.c_str(), s.size() + 1);
      g_slots[i].state.store(kLive, std::memory_order_release);
      return i;
    }
  }
  throw Error("more than " + std::to_string(kSlots) +
              " outputs are being written at once; write fewer files per run");
}

void forget_temp(int slot) {
  if (slot >= 0 && slot < kSlots) g_slots[slot].state.store(kFree, std::memory_order_release);
}

bool stop_wanted_for_tests(TestPoint point) { return wanted_count(point) > 0; }

void stop_here_for_tests(TestPoint point) {
  static std::atomic<int> writes{0}, reports{0};
  const int wanted = wanted_count(point);
  if (wanted <= 0) return;
  std::atomic<int>& count = point == TestPoint::write ? writes : reports;
  if (count.fetch_add(1) + 1 != wanted) return;
  raise(SIGSTOP);
  if (std::getenv("DRIFT_TEST_AWAIT_SIGNAL")) {
    for (;;) pause();  // the signal thread ends the process
  }
}

DeferSignals::DeferSignals(bool renaming) {
  g_defer.lock();
  if (renaming) g_renames.fetch_add(1);
}

DeferSignals::~DeferSignals() { g_defer.unlock(); }

}  // namespace drift
