#include "terrain/output_path.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>

#include "terrain/error.h"

namespace drift {

namespace fs = std::filesystem;

namespace {

fs::path directory_of(const fs::path& target) {
  const fs::path dir = target.parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

// (Built with append: GCC 12 warns falsely on `"'" + std::string`, bug 105651.)
std::string quoted(const fs::path& p) {
  std::string s = "'";
  s.append(p.string()).append("'");
  return s;
}

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

long name_limit(const fs::path& dir) {
  const long limit = pathconf(dir.c_str(), _PC_NAME_MAX);
  return limit > 0 ? limit : 255;
}

void check_existing_target(const fs::path& target) {
  struct stat st {};
  if (lstat(target.c_str(), &st) != 0) return;  // a new file
  if (S_ISLNK(st.st_mode)) {
    std::error_code ec;
    const fs::path to = fs::read_symlink(target, ec);
    throw Error("will not write output " + quoted(target) + ": it is a symbolic link (to " +
                quoted(to) + "); outputs are never written through links: give the real path or " +
                "remove the link");
  }
  if (!S_ISREG(st.st_mode)) {
    throw Error("will not write output " + quoted(target) + ": it is " + kind_of(st.st_mode) +
                ", not a regular file; give a file name");
  }
}

void check_directory(const fs::path& target) {
  const fs::path dir = directory_of(target);
  struct stat st {};
  if (stat(dir.c_str(), &st) != 0) {
    throw Error("cannot write " + quoted(target) + ": directory " + quoted(dir) +
                " does not exist; create it first");
  }
  if (!S_ISDIR(st.st_mode)) {
    throw Error("cannot write " + quoted(target) + ": " + quoted(dir) + " is not a directory");
  }
  if (access(dir.c_str(), W_OK) != 0) {
    throw Error("cannot write " + quoted(target) + ": directory " + quoted(dir) +
                " is not writable");
  }
  const std::size_t length = target.filename().native().size();
  if (static_cast<long>(length) > name_limit(dir)) {
    throw Error("cannot write " + quoted(target) + ": its name is " + std::to_string(length) +
                " bytes, more than the " + std::to_string(name_limit(dir)) +
                " the file system allows; use a shorter name");
  }
}

void check_not_input(const fs::path& target, const std::vector<fs::path>& inputs) {
  for (const fs::path& input : inputs) {
    if (input.empty()) continue;
    std::error_code ec;
    if (fs::equivalent(target, input, ec) && !ec) {
      throw Error("will not write output " + quoted(target) + ": it is the input " + quoted(input) +
                  " of this run, which would be overwritten; give another name");
    }
  }
}

// From /proc (umask() itself would change it, for a moment, for every thread).
mode_t current_umask() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("Umask:", 0) == 0)
      return static_cast<mode_t>(std::stoul(line.substr(6), nullptr, 8));
  }
  return 022;
}

}  // namespace

void check_output_path(const fs::path& target, const std::vector<fs::path>& inputs) {
  if (target.empty()) throw Error("an output path is empty; give a file name");
  if (!target.has_filename() || target.filename() == "." || target.filename() == "..") {
    throw Error("cannot write " + quoted(target) + ": it names a directory; give a file name");
  }
  check_existing_target(target);
  check_directory(target);
  check_not_input(target, inputs);
}

fs::path create_temp_beside(const fs::path& target) {
  const fs::path dir = directory_of(target);
  const std::string marker = ".tmp-XXXXXX";  // mkstemps fills the X's
  std::string stem = target.stem().native(), ext = target.extension().native();
  // ".<stem>.tmp-XXXXXX<ext>" within the name limit: trim the stem, then the extension.
  const std::size_t limit = static_cast<std::size_t>(name_limit(dir));
  const std::size_t fixed = 1 + marker.size();
  if (fixed + ext.size() > limit) ext.clear();
  if (fixed + ext.size() + stem.size() > limit) stem.resize(limit - fixed - ext.size());
  std::string name = (dir / ("." + stem + marker + ext)).native();
  const int fd = mkstemps(name.data(), static_cast<int>(ext.size()));
  if (fd < 0) {
    throw Error("cannot create a temporary file beside " + quoted(target) + ": " +
                std::strerror(errno) + " (is the directory writable and the disk not full?)");
  }
  close(fd);
  return name;
}

void match_permissions(const fs::path& temp, const fs::path& target) {
  struct stat st {};
  if (stat(target.c_str(), &st) == 0) {
    chmod(temp.c_str(), st.st_mode & 07777);
    if (st.st_uid != geteuid() || st.st_gid != getegid()) {
      // Only root may give a file away; others keep their own ownership.
      const int ignored = chown(temp.c_str(), st.st_uid, st.st_gid);
      (void)ignored;
      chmod(temp.c_str(), st.st_mode & 07777);  // chown clears set-id bits
    }
    return;
  }
  chmod(temp.c_str(), 0666 & ~current_umask());
}

}  // namespace drift
