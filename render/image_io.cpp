// Image files through OpenImageIO 2.4. EXR keeps linear float channels as
// stored; 8/16-bit formats are display-referred sRGB and are decoded to linear
// on read and encoded (after the DisplayTransform) on write. Every output goes
// through drift::AtomicFile: a failed write leaves no file behind.
#include "render/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>

#include "render/auto_exposure.h"
#include "terrain/atomic_file.h"
#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::render {

namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::string oiio_message(const std::string& detail) {
  return detail.empty() ? std::string("unknown OpenImageIO error") : detail;
}

// Opens `path` for writing as `spec`, writes float pixels and closes; any
// failure (including a failed close, which is where buffered formats flush)
// throws naming the target.
void write_with_oiio(const std::filesystem::path& target, const std::filesystem::path& temp,
                     const OIIO::ImageSpec& spec, const OIIO::TypeDesc& pixel_type,
                     const void* data) {
  auto out = OIIO::ImageOutput::create(temp.string());
  if (!out) {
    throw Error("cannot write image " + target.string() + ": " + oiio_message(OIIO::geterror()));
  }
  if (!out->open(temp.string(), spec) || !out->write_image(pixel_type, data) || !out->close()) {
    throw Error("cannot write image " + target.string() + ": " + oiio_message(out->geterror()) +
                " (check the disk space and that the folder is writable)");
  }
}

// Linear data as stored, channel names kept (EXR names AOVs "albedo.R" etc.),
// with the data window and drift's own attributes.
Image linear_image(const OIIO::ImageSpec& spec, std::vector<float> raw) {
  const int nc = spec.nchannels;
  std::vector<std::string> names;
  for (int c = 0; c < nc; ++c) {
    std::string name =
        c < static_cast<int>(spec.channelnames.size()) ? spec.channelnames[c] : std::string();
    if (name.empty()) name = "channel" + std::to_string(c);
    names.push_back(name);
  }
  Image image(spec.width, spec.height, names);
  image.pixels = std::move(raw);
  if (spec.x != 0 || spec.y != 0 || spec.full_width != spec.width ||
      spec.full_height != spec.height) {
    image.frame = {spec.x, spec.y, spec.full_width, spec.full_height};
  }
  for (const OIIO::ParamValue& p : spec.extra_attribs) {
    const std::string name = p.name().string();
    if (name.rfind("drift:", 0) == 0 && p.type() == OIIO::TypeDesc::STRING) {
      image.attributes.emplace_back(name.substr(6), p.get_string());
    }
  }
  return image;
}

// Display-referred integer image: sRGB-decode to linear R, G, B[, A]. Grey
// (1 channel) and grey+alpha (2 channels) are spread over R, G, B.
Image display_image(const OIIO::ImageSpec& spec, const std::vector<float>& raw) {
  const int nc = spec.nchannels;
  const bool has_alpha = spec.alpha_channel >= 0 || nc == 2 || nc >= 4;
  const int colour = nc >= 3 ? 3 : 1;
  std::vector<std::string> names = {"R", "G", "B"};
  if (has_alpha) names.push_back("A");
  Image image(spec.width, spec.height, names);
  const int alpha_src = nc == 2 ? 1 : (nc >= 4 ? 3 : -1);
  const std::size_t n = static_cast<std::size_t>(spec.width) * spec.height;
  for (std::size_t p = 0; p < n; ++p) {
    const float* s = &raw[p * nc];
    float* d = &image.pixels[p * names.size()];
    for (int c = 0; c < 3; ++c) d[c] = srgb_decode(s[colour == 3 ? c : 0]);
    if (has_alpha) d[3] = alpha_src >= 0 ? s[alpha_src] : 1.0f;  // alpha is linear coverage
  }
  return image;
}

// OpenEXR 3.1 allocates an attribute of a type it does not know at the size
// the file declares before reading it: a 973-byte EXR declaring a 1.9 GB
// attribute had 1.9 GB allocated, a 46-byte one took 5 s (found by
// fuzz_image). Walks the header(s) as OpenEXR reads them (magic, version, then
// `name\0 type\0 int32 size, value` until an empty name, names of at most 31
// characters, 255 with the long-names flag; multi-part files repeat headers
// until an empty one) and refuses a size beyond the file's end. Partial: a
// known type's value (a channel list) is parsed by its content, and where that
// disagrees with its declared size OpenEXR reads on from elsewhere.
void check_exr_attribute_sizes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char magic[8] = {};
  if (!in.read(reinterpret_cast<char*>(magic), 8) || magic[0] != 0x76 || magic[1] != 0x2f ||
      magic[2] != 0x31 || magic[3] != 0x01)
    return;  // not an EXR: its reader checks it
  const bool multipart = magic[5] & 0x10, long_names = magic[5] & 0x04;
  const std::uint64_t file_size = std::filesystem::file_size(path);
  const auto read_name = [&in, max = long_names ? 255 : 31](std::string& name) {
    name.clear();  // as OpenEXR's Xdr::read: up to max + 1 characters or a null
    for (char c; name.size() <= static_cast<std::size_t>(max) && in.get(c) && c != '\0';)
      name.push_back(c);
    return static_cast<bool>(in);
  };
  std::string name, type;
  for (int attributes = 0; attributes < 100000; ++attributes) {
    if (!read_name(name)) return;  // truncated: OpenEXR says so
    if (name.empty()) {
      if (!multipart || in.peek() == '\0' || in.peek() == EOF) return;
      continue;  // the next part's header
    }
    std::int32_t size = 0;
    if (!read_name(type) || !in.read(reinterpret_cast<char*>(&size), 4)) return;
    const std::uint64_t at = static_cast<std::uint64_t>(in.tellg());
    if (size < 0 || static_cast<std::uint64_t>(size) > file_size - std::min(at, file_size)) {
      throw Error("cannot read image " + path.string() + ": its header attribute '" + name +
                  "' declares " + std::to_string(size) + " bytes but the file holds " +
                  std::to_string(file_size) + " (the file is corrupt)");
    }
    in.seekg(size, std::ios::cur);
  }
}

}  // namespace

Image read_image(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error("image " + path.string() + " does not exist or is not a file; check the path");
  }
  check_exr_attribute_sizes(path);
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) {
    throw Error("cannot read image " + path.string() + ": " + oiio_message(OIIO::geterror()) +
                " (expected EXR, PNG, JPEG or TIFF)");
  }
  const OIIO::ImageSpec spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1 || spec.depth > 1) {
    throw Error("image " + path.string() + " has an unsupported shape (" +
                std::to_string(spec.width) + "x" + std::to_string(spec.height) + ", " +
                std::to_string(spec.nchannels) + " channels)");
  }
  const int nc = spec.nchannels;
  // Decoded as float and then copied: twice the declared size (a small PNG can
  // declare 60000^2 pixels).
  require_memory(static_cast<std::uint64_t>(spec.width) * spec.height * nc * sizeof(float) * 2,
                 "image " + path.string() + " (" + std::to_string(spec.width) + "x" +
                     std::to_string(spec.height) + ", " + std::to_string(nc) + " channels)",
                 "use a smaller image");
  std::vector<float> raw(static_cast<std::size_t>(spec.width) * spec.height * nc);
  const bool ok = in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, raw.data());
  const std::string read_error = ok ? std::string() : in->geterror();
  in->close();
  if (!ok) {
    throw Error("cannot read the pixels of image " + path.string() + ": " +
                oiio_message(read_error) + " (the file may be truncated or corrupt)");
  }
  const bool is_float_format = spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                               spec.format.basetype == OIIO::TypeDesc::HALF ||
                               spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  const bool is_exr =
      lower_extension(path) == ".exr" || std::string(in->format_name()) == "openexr";
  if (is_exr || is_float_format) return linear_image(spec, std::move(raw));
  return display_image(spec, raw);
}

void write_exr(const Image& image, const std::filesystem::path& path) {
  if (lower_extension(path) != ".exr") {
    throw Error("EXR output " + path.string() + " must end in .exr");
  }
  if (image.width < 1 || image.height < 1 || image.channels.empty() ||
      image.pixels.size() !=
          static_cast<std::size_t>(image.width) * image.height * image.channels.size()) {
    throw Error("cannot write " + path.string() +
                ": the image is empty or its pixel count does "
                "not match its size and channels");
  }
  AtomicFile file(path);
  OIIO::ImageSpec spec(image.width, image.height, image.channel_count(), OIIO::TypeDesc::FLOAT);
  spec.channelnames = image.channels;
  spec.alpha_channel = image.channel_index("A");
  spec.attribute("compression", "zip");
  if (image.frame.full_width > 0 && image.frame.full_height > 0) {
    spec.x = image.frame.x;
    spec.y = image.frame.y;
    spec.full_x = spec.full_y = 0;
    spec.full_width = image.frame.full_width;
    spec.full_height = image.frame.full_height;
  }
  for (const auto& [name, value] : image.attributes) spec.attribute("drift:" + name, value);
  // No creation date: OpenImageIO stamps the current time into capDate when
  // none is given, and two runs of one scene would differ in their bits
  // (same inputs and seed, same output). The file's time says when.
  spec.attribute("DateTime", "");
  write_with_oiio(path, file.temp_path(), spec, OIIO::TypeDesc::FLOAT, image.pixels.data());
  file.commit();
}

static std::vector<std::uint8_t> to_srgb8(const Image& linear, const DisplayTransform& display,
                                          const std::filesystem::path& path) {
  int r = linear.channel_index("R"), g = linear.channel_index("G"), b = linear.channel_index("B");
  if (r < 0 || g < 0 || b < 0) {
    if (linear.channel_count() != 1) {
      throw Error("cannot write " + path.string() +
                  " as PNG: the image has no R, G, B channels and more than one channel; "
                  "write it as .exr instead");
    }
    r = g = b = 0;  // a single channel (depth, mask, height) shows as grey
  }
  const std::size_t n = static_cast<std::size_t>(linear.width) * linear.height;
  std::vector<std::uint8_t> out(n * 3);
  const int idx[3] = {r, g, b};
  for (std::size_t p = 0; p < n; ++p) {
    const float* s = &linear.pixels[p * linear.channels.size()];
    for (int c = 0; c < 3; ++c) {
      const float e = srgb_encode(apply_tone_curve(s[idx[c]] * display.white_balance[c], display));
      // Round to nearest: deterministic, and decode->encode round trips exactly.
      out[p * 3 + c] = static_cast<std::uint8_t>(std::lround(e * 255.0f));
    }
  }
  return out;
}

DisplayTransform resolve_exposure(const Image& linear, const DisplayTransform& display) {
  if (!display.auto_exposure) return display;
  DisplayTransform fixed = display;
  // The meter brings a grey card to 0.18 before the curve; a camera shows it
  // at 0.18 after it (ISO 12232 standard output, render/tonemap.h).
  fixed.exposure_ev +=
      meter_exposure(linear, display.white_balance).exposure_ev + middle_grey_ev(display.curve);
  fixed.auto_exposure = false;
  return fixed;
}

void write_png(const Image& linear, const std::filesystem::path& path,
               const DisplayTransform& display) {
  if (lower_extension(path) != ".png") {
    throw Error("PNG output " + path.string() + " must end in .png");
  }
  if (linear.width < 1 || linear.height < 1 ||
      linear.pixels.size() !=
          static_cast<std::size_t>(linear.width) * linear.height * linear.channels.size()) {
    throw Error("cannot write " + path.string() + ": the image is empty or inconsistent");
  }
  if (!std::isfinite(display.exposure_ev) || std::abs(display.exposure_ev) > 64.0) {
    throw Error("exposure " + std::to_string(display.exposure_ev) + " EV for " + path.string() +
                " is out of range; use a value in [-64, 64]");
  }
  const std::vector<std::uint8_t> bytes = to_srgb8(linear, resolve_exposure(linear, display), path);
  AtomicFile file(path);
  OIIO::ImageSpec spec(linear.width, linear.height, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  write_with_oiio(path, file.temp_path(), spec, OIIO::TypeDesc::UINT8, bytes.data());
  file.commit();
}

void write_image(const Image& image, const std::filesystem::path& path,
                 const DisplayTransform& display) {
  const std::string ext = lower_extension(path);
  if (ext == ".exr") {
    write_exr(image, path);
  } else if (ext == ".png") {
    write_png(image, path, display);
  } else {
    throw Error("cannot write image " + path.string() + ": unknown extension '" + ext +
                "'; use .exr (linear float) or .png (8-bit sRGB)");
  }
}

}  // namespace drift::render
