#include "terrain/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include "terrain/error.h"
#include "terrain/output_path.h"
#include "terrain/output_set.h"
#include "terrain/temp_registry.h"

namespace drift {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  stop_here_for_tests();
  if (OutputSet::Staged* s = OutputSet::staged(target_)) {
    temp_ = s->temp;
    staged_ = true;
    return;
  }
  check_output_path(target_, OutputSet::open_inputs());
  DeferSignals defer;  // a signal between creating and recording would leave the file
  temp_ = create_temp_beside(target_);
  try {
    slot_ = register_temp(temp_);
  } catch (...) {
    std::error_code ec;
    fs::remove(temp_, ec);
    throw;
  }
}

AtomicFile::~AtomicFile() {
  if (staged_) return;  // the set removes its own temporary files
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
  forget_temp(slot_);
}

void AtomicFile::commit() {
  std::error_code ec;
  if (!fs::exists(temp_, ec)) {
    throw Error("internal: nothing was written for '" + target_.string() + "'");
  }
  if (staged_) {
    if (OutputSet::Staged* s = OutputSet::staged(target_)) s->written = true;
    committed_ = true;
    return;
  }
  match_permissions(temp_, target_);
  DeferSignals defer(true);
  fs::rename(temp_, target_, ec);
  if (ec) {
    throw Error("cannot move finished output onto '" + target_.string() + "': " + ec.message());
  }
  committed_ = true;
  forget_temp(slot_);
  slot_ = -1;
}

std::string write_failure_reason(const fs::path& target, int error) {
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    return "its folder '" + folder.string() + "' was removed during the run";
  return std::strerror(error != 0 ? error : EIO);
}

void write_all_bytes(const fs::path& temp, const void* data, std::size_t size,
                     const fs::path& target) {
  const auto fail = [&](int error) {
    throw Error("cannot write '" + target.string() + "': " + write_failure_reason(target, error) +
                " (the existing file, if any, is left as it was)");
  };
  const int fd = ::open(temp.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (fd < 0) fail(errno);
  const char* bytes = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, bytes, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : ENOSPC;
      ::close(fd);
      fail(error);
    }
    bytes += n;
    size -= static_cast<std::size_t>(n);
  }
  // A network or quota file system may report a failure only here.
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
    const int error = errno;
    ::close(fd);
    fail(error);
  }
  if (::close(fd) != 0) fail(errno);
}

}  // namespace drift
