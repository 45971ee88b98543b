#include "terrain/output_set.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <mutex>
#include <string>
#include <system_error>

#include "terrain/error.h"
#include "terrain/output_path.h"
#include "terrain/temp_registry.h"

namespace drift {

namespace fs = std::filesystem;

namespace {

std::mutex g_mutex;
OutputSet* g_open = nullptr;  // one run, one set

fs::path normal(const fs::path& p) {
  std::error_code ec;
  const fs::path a = fs::absolute(p, ec);
  return (ec ? p : a).lexically_normal();
}

// Puts the old target aside under a second name (a hard link) so that a failed
// commit can restore it; empty if there is no old target or no link was possible.
fs::path keep_old(const fs::path& target, const fs::path& temp) {
  std::error_code ec;
  if (!fs::exists(target, ec)) return {};
  fs::path old = temp;
  old += ".old";
  return link(target.c_str(), old.c_str()) == 0 ? old : fs::path();
}

// Exclusive advisory locks (flock) on the folders of a set's outputs, taken in
// sorted order so that two runs never wait on each other crosswise. Runs whose
// outputs share a folder replace their outputs one set after the other, so two
// runs writing the same files at once leave one run's outputs, never a mix
// (issue 34, class 7). Held only while renaming, so `make -j` over one folder
// keeps its parallelism. Best effort: a file system without flock (some network
// mounts) commits unlocked, as before.
class FolderLocks {
 public:
  explicit FolderLocks(const std::vector<OutputSet::Staged>& outputs) {
    std::vector<fs::path> folders;
    for (const OutputSet::Staged& s : outputs) {
      std::error_code ec;
      const fs::path folder = fs::canonical(normal(s.target).parent_path(), ec);
      if (!ec) folders.push_back(folder);
    }
    std::sort(folders.begin(), folders.end());
    folders.erase(std::unique(folders.begin(), folders.end()), folders.end());
    for (const fs::path& folder : folders) {
      const int fd = open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
      if (fd < 0) continue;
      int status;
      while ((status = flock(fd, LOCK_EX)) != 0 && errno == EINTR) {
      }
      if (status != 0) {
        close(fd);
        continue;
      }
      fds_.push_back(fd);
    }
  }
  ~FolderLocks() {
    for (const int fd : fds_) close(fd);  // closing the last descriptor releases the lock
  }
  FolderLocks(const FolderLocks&) = delete;
  FolderLocks& operator=(const FolderLocks&) = delete;

 private:
  std::vector<int> fds_;
};

}  // namespace

OutputSet::OutputSet(const std::vector<fs::path>& outputs, std::vector<fs::path> inputs)
    : inputs_(std::move(inputs)) {
  std::erase_if(inputs_, [](const fs::path& p) { return p.empty(); });
  try {
    for (const fs::path& target : outputs) {
      if (!target.empty()) stage(target);
    }
  } catch (...) {
    remove_temps();
    throw;
  }
  std::lock_guard lock(g_mutex);
  if (g_open) {
    remove_temps();
    throw Error("internal: two output sets are open at once");
  }
  g_open = this;
}

void OutputSet::stage(const fs::path& target) {
  for (const Staged& s : outputs_) {
    std::error_code ec;
    if (normal(s.target) == normal(target) || fs::equivalent(s.target, target, ec)) {
      throw Error("output '" + target.string() + "' is given twice (also as '" + s.target.string() +
                  "'); give each output its own file");
    }
  }
  check_output_path(target, inputs_);
  DeferSignals defer;  // a signal between creating and recording would leave the file
  Staged s{target, create_temp_beside(target)};
  try {
    s.slot = register_temp(s.temp);
  } catch (...) {
    std::error_code ec;
    fs::remove(s.temp, ec);
    throw;
  }
  outputs_.push_back(std::move(s));
}

OutputSet::~OutputSet() {
  {
    std::lock_guard lock(g_mutex);
    if (g_open == this) g_open = nullptr;
  }
  if (!committed_) remove_temps();
}

void OutputSet::remove_temps() {
  for (Staged& s : outputs_) {
    std::error_code ec;
    fs::remove(s.temp, ec);
    forget_temp(s.slot);
    s.slot = -1;
  }
}

void OutputSet::commit() {
  for (const Staged& s : outputs_) {
    if (!s.written) throw Error("internal: output '" + s.target.string() + "' was not written");
  }
  for (const Staged& s : outputs_) match_permissions(s.temp, s.target);
  // Taken before signals are deferred: a run waiting here can still be stopped.
  const FolderLocks locks(outputs_);
  DeferSignals defer(true);
  std::vector<fs::path> old(outputs_.size());
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    old[i] = keep_old(outputs_[i].target, outputs_[i].temp);
    std::error_code ec;
    fs::rename(outputs_[i].temp, outputs_[i].target, ec);
    if (ec) {
      // Undo: the outputs already replaced get their old contents back.
      for (std::size_t j = 0; j <= i; ++j) {
        std::error_code ignored;
        if (j < i && !old[j].empty()) fs::rename(old[j], outputs_[j].target, ignored);
        if (j < i && old[j].empty()) fs::remove(outputs_[j].target, ignored);
        if (j == i && !old[j].empty()) fs::remove(old[j], ignored);
      }
      throw Error("cannot move finished output onto '" + outputs_[i].target.string() +
                  "': " + ec.message() + "; no output was replaced");
    }
  }
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    std::error_code ignored;
    if (!old[i].empty()) fs::remove(old[i], ignored);
    forget_temp(outputs_[i].slot);
    outputs_[i].slot = -1;
  }
  committed_ = true;
}

OutputSet::Staged* OutputSet::staged(const fs::path& target) {
  std::lock_guard lock(g_mutex);
  if (!g_open) return nullptr;
  const fs::path wanted = normal(target);
  for (Staged& s : g_open->outputs_) {
    if (normal(s.target) == wanted) return &s;
  }
  return nullptr;
}

std::vector<fs::path> OutputSet::open_inputs() {
  std::lock_guard lock(g_mutex);
  return g_open ? g_open->inputs_ : std::vector<fs::path>{};
}

}  // namespace drift
