#include "terrain/temp_registry.h"

#include <limits.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include "terrain/error.h"

namespace drift {

namespace {

// A fixed table, no allocation: the handler may only read plain memory and call
// async-signal-safe functions (unlink, write, _exit).
constexpr int kSlots = 64;
enum : int { kFree = 0, kFilling = 1, kLive = 2 };
struct Slot {
  std::atomic<int> state{kFree};
  char path[PATH_MAX];
};
Slot g_slots[kSlots];
std::atomic<int> g_deferring{0};  // > 0 while outputs are being renamed into place
std::atomic<int> g_pending{0};    // a signal that came meanwhile
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

void write_text(const char* s) {
  const ssize_t ignored = write(STDERR_FILENO, s, std::strlen(s));
  (void)ignored;
}

// Removes every live temporary file, says so in one line and exits 128 + sig.
[[noreturn]] void clean_up_and_exit(int sig, const char* outcome) {
  for (Slot& slot : g_slots) {
    if (slot.state.load(std::memory_order_acquire) == kLive) unlink(slot.path);
  }
  const char* name = sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "SIGHUP";
  write_text("drift: interrupted by ");
  write_text(name);
  write_text(outcome);
  _exit(128 + sig);
}

extern "C" void on_cleanup_signal(int sig) {
  if (g_deferring.load() > 0) {
    g_pending.store(sig);
    return;
  }
  clean_up_and_exit(sig, "; temporary files removed, existing outputs left as they were\n");
}

sigset_t cleanup_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  return set;
}

}  // namespace

void install_signal_cleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction action {};
    action.sa_handler = on_cleanup_signal;
    action.sa_mask = cleanup_signals();  // one handler at a time
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &action, nullptr);
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

void stop_here_for_tests() {
  static const char* wanted = std::getenv("DRIFT_TEST_STOP_AT_WRITE");
  static std::atomic<int> writes{0};
  if (wanted && writes.fetch_add(1) + 1 == std::atoi(wanted)) raise(SIGSTOP);
}

DeferSignals::DeferSignals(bool renaming) : renaming_(renaming) { g_deferring.fetch_add(1); }

DeferSignals::~DeferSignals() {
  if (g_deferring.fetch_sub(1) == 1) {
    if (const int sig = g_pending.exchange(0)) {
      clean_up_and_exit(
          sig, renaming_ ? " while the outputs were moved into place; they are all complete\n"
                         : "; temporary files removed, existing outputs left as they were\n");
    }
  }
}

}  // namespace drift
