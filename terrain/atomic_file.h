// Writes an output through a temporary file in the same directory and renames it
// into place on commit(), so a failed or interrupted run never leaves a
// half-written file and never replaces a good one with a bad one.
#pragma once

#include <filesystem>

namespace drift {

class AtomicFile {
 public:
  // Checks that the target's directory exists and is writable; throws drift::Error
  // naming the path otherwise.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();  // removes the temporary file unless commit() succeeded
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Where the writer must write. Keeps the target's extension, so that libraries
  // that choose a format by extension (OpenImageIO, GDAL) still do.
  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }

  // Renames the temporary file onto the target (atomic on POSIX).
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool committed_ = false;
};

}  // namespace drift
