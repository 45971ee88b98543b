// The rule every input file obeys: it exists and is a regular file (a link to
// one is fine). A FIFO, device or directory is refused before it is opened, so
// that no reader blocks on a pipe or reads a device forever.
#pragma once

#include <filesystem>
#include <string>

namespace drift {

// Throws drift::Error "cannot read <what> '<path>': ..." naming what is wrong.
void check_input_file(const std::filesystem::path& path, const std::string& what);

}  // namespace drift
