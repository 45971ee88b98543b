#include "terrain/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <system_error>

#include "terrain/error.h"

namespace drift {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  if (target_.empty()) throw Error("output path is empty: give a file name with -o");
  fs::path dir = target_.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw Error("cannot write '" + target_.string() + "': directory '" + dir.string() +
                "' does not exist; create it first");
  }
  if (fs::is_directory(target_, ec)) {
    throw Error("cannot write '" + target_.string() + "': it is a directory; give a file name");
  }
  if (access(dir.c_str(), W_OK) != 0) {
    throw Error("cannot write '" + target_.string() + "': directory '" + dir.string() +
                "' is not writable");
  }
  static std::atomic<int> counter{0};
  // ".name.tmp-PID-N.ext": hidden, unique per process and call, same extension.
  // (Built with append: GCC 12 warns falsely on `"." + std::string`, bug 105651.)
  std::string name = ".";
  name.append(target_.stem().string())
      .append(".tmp-")
      .append(std::to_string(getpid()))
      .append("-")
      .append(std::to_string(counter++))
      .append(target_.extension().string());
  temp_ = dir / name;
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicFile::commit() {
  std::error_code ec;
  if (!fs::exists(temp_, ec)) {
    throw Error("internal: nothing was written for '" + target_.string() + "'");
  }
  fs::rename(temp_, target_, ec);
  if (ec) {
    throw Error("cannot move finished output onto '" + target_.string() + "': " + ec.message());
  }
  committed_ = true;
}

}  // namespace drift
