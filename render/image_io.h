// Image files through OpenImageIO: EXR (linear, all channels kept) and PNG
// (display-referred 8-bit sRGB, tone-mapped from linear radiance).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "render/image.h"
#include "render/tonemap.h"

namespace drift::render {

// EXR: every channel as stored (linear). PNG/JPEG/TIFF with 8 or 16 bits: decoded
// from sRGB to linear, channels "R", "G", "B" (and "A" if present). Throws
// drift::Error naming the file if it is missing, unreadable or not an image.
Image read_image(const std::filesystem::path& path);

// Float32 EXR with ZIP compression holding every channel; written atomically.
void write_exr(const Image& image, const std::filesystem::path& path);

// 8-bit sRGB PNG of the R, G, B channels after `display` (exposure, metered
// if display.auto_exposure, tone curve); written atomically.
void write_png(const Image& linear, const std::filesystem::path& path,
               const DisplayTransform& display = {});

// `display` with a metered exposure (render/auto_exposure.h) made fixed:
// its exposure_ev added to the meter's, and the tone curve's middle_grey_ev
// (render/tonemap.h), when auto_exposure is on.
DisplayTransform resolve_exposure(const Image& linear, const DisplayTransform& display);

// The 8-bit sRGB bytes (R, G, B interleaved) write_png would write, for
// other writers (render/map_output.h); `path` names the target in errors.
std::vector<std::uint8_t> display_pixels(const Image& linear, const DisplayTransform& display,
                                         const std::filesystem::path& path);

// Chooses by extension: .exr or .png (case-insensitive); anything else is an
// error naming the path and the extensions allowed.
void write_image(const Image& image, const std::filesystem::path& path,
                 const DisplayTransform& display = {});

}  // namespace drift::render
