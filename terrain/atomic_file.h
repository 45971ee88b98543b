// Writes one output through a private temporary file beside it and renames it
// into place on commit(), so a failed or interrupted run never leaves a
// half-written file and never replaces a good one with a bad one. The target
// must pass check_output_path (terrain/output_path.h). When the target belongs
// to the run's open OutputSet (terrain/output_set.h), the set's temporary file
// is used and the set renames all its outputs together.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

namespace drift {

class AtomicFile {
 public:
  // Checks the target and creates the temporary file; throws drift::Error naming
  // the path if it cannot be an output.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();  // removes the temporary file unless commit() succeeded
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Where the writer must write. Keeps the target's extension, so that libraries
  // that choose a format by extension (OpenImageIO, GDAL) still do.
  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }

  // Renames the temporary file onto the target (atomic on POSIX), keeping an
  // existing target's permissions; within an OutputSet, marks it complete.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  int slot_ = -1;        // in the signal handler's table of temporary files
  bool staged_ = false;  // the temporary file belongs to an OutputSet
  bool committed_ = false;
};

// Writes `size` bytes to `temp` (an AtomicFile's temporary file), checking
// every write, the flush and the close; throws drift::Error naming `target` and
// the system's reason ("No space left on device"). For writers whose library
// does not report a failed flush (OpenImageIO's PNG, OpenVDB's streams): they
// encode into memory and this writes the bytes.
void write_all_bytes(const std::filesystem::path& temp, const void* data, std::size_t size,
                     const std::filesystem::path& target);

// Why writing `target` failed, after the system's `error`: "its folder 'out'
// was removed during the run" when it was (a deleted output folder read as
// "disk full?", issue 34), else the system's reason ("No space left on device").
std::string write_failure_reason(const std::filesystem::path& target, int error);

}  // namespace drift
