#include "terrain/input_path.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "terrain/error.h"

namespace drift {

void check_input_file(const std::filesystem::path& path, const std::string& what) {
  const std::string head = "cannot read " + what + " '" + path.string() + "': ";
  if (path.empty()) throw Error("cannot read " + what + ": the path is empty; give a file");
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) {
    throw Error(head + (errno == ENOENT ? std::string("no such file") : std::strerror(errno)));
  }
  if (S_ISDIR(st.st_mode)) throw Error(head + "it is a directory, not a file");
  if (!S_ISREG(st.st_mode)) {
    throw Error(head + "it is a device, FIFO or socket, not a regular file; give a file");
  }
}

}  // namespace drift
