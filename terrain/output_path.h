// The rules every output path obeys, in one place (docs/outputs.md):
// - it is a regular file or does not exist yet: a directory, device, FIFO or
//   socket is refused (writing "-o /dev/null" as root would replace the device);
// - it is not a symbolic link: links are refused, never written through, so a
//   link planted where an output goes cannot redirect the write;
// - it is not one of the run's inputs (compared as files, so another spelling,
//   a hard link or a link to an input counts);
// - its directory exists and is writable, and its name fits the file system.
#pragma once

#include <filesystem>
#include <vector>

namespace drift {

// Throws drift::Error naming `target`, what is wrong and the fix.
void check_output_path(const std::filesystem::path& target,
                       const std::vector<std::filesystem::path>& inputs = {});

// Creates a private, empty temporary file beside `target` (mode 0600, created
// exclusively under an unpredictable name; hidden; the target's extension kept so
// that libraries choosing a format by extension still do; the name trimmed to
// the file system's limit). Throws drift::Error if it cannot.
std::filesystem::path create_temp_beside(const std::filesystem::path& target);

// Gives the finished `temp` the permissions `target` has, or those a new file
// gets (0666 less the umask), and the owner of an existing target when we may.
void match_permissions(const std::filesystem::path& temp, const std::filesystem::path& target);

}  // namespace drift
