// An EXR's header parsed first with every allocation bounded by the file's
// size, so that a small file cannot make OpenEXR reserve gigabytes.
#pragma once

#include <filesystem>

namespace drift::render {

// True if the file starts with the EXR magic number (0x762f3101).
bool has_exr_magic(const std::filesystem::path& path);

// Parses the header(s) of the EXR at `path` with OpenEXRCore, as
// OpenImageIO's OpenEXRCore reader (selected by read_image) will parse them,
// but refusing any single allocation larger than twice the file plus 1 MiB.
// Throws drift::Error naming the file if an allocation was refused (the header
// declares more than the file holds) or the header is invalid.
void validate_exr_header(const std::filesystem::path& path);

}  // namespace drift::render
