// Image files through OpenImageIO 2.4. EXR keeps linear float channels as
// stored; 8/16-bit formats are display-referred sRGB and are decoded to linear
// on read and encoded (after the DisplayTransform) on write. Every output goes
// through drift::AtomicFile: a failed write leaves no file behind.
#include "render/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <vector>

#include "render/auto_exposure.h"
#include "render/exr_header.h"
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
// throws naming the target. The file is encoded in memory and written with every
// write checked, because OpenImageIO reports no failed flush: on a full disk its
// PNG and EXR writers left an empty or truncated file and exit status 0. The
// encoded bytes are at most about the pixels' own size, which the callers have
// checked against memory already.
void write_with_oiio(const std::filesystem::path& target, const std::filesystem::path& temp,
                     const OIIO::ImageSpec& spec, const OIIO::TypeDesc& pixel_type,
                     const void* data) {
  auto out = OIIO::ImageOutput::create(temp.string());
  if (!out) {
    throw Error("cannot write image " + target.string() + ": " + oiio_message(OIIO::geterror()));
  }
  std::vector<unsigned char> encoded;
  OIIO::Filesystem::IOVecOutput proxy(encoded);
  if (!out->supports("ioproxy") || !out->set_ioproxy(&proxy)) {
    throw Error("internal: cannot encode " + target.string() + " in memory");
  }
  if (!out->open(temp.string(), spec) || !out->write_image(pixel_type, data) || !out->close()) {
    throw Error("cannot write image " + target.string() + ": " + oiio_message(out->geterror()) +
                " (check the disk space and that the folder is writable)");
  }
  write_all_bytes(temp, encoded.data(), encoded.size(), target);
}

// The header attributes drift writes under their own names and keeps on
// reading (so `drift merge` passes them on): OpenEXR's camera matrices, the
// georeference, Cryptomatte's metadata.
bool is_header_attribute(const std::string& name) {
  return name == "worldToCamera" || name == "worldToNDC" || name == "worldOrigin" ||
         name == "crsWKT" || name.rfind("cryptomatte/", 0) == 0;
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
    } else if (is_header_attribute(name) && p.type() == OIIO::TypeDesc::STRING) {
      image.header_texts.emplace_back(name, p.get_string());
    } else if (is_header_attribute(name) && p.type() == OIIO::TypeMatrix44) {
      std::array<float, 16> m{};
      std::memcpy(m.data(), p.data(), sizeof m);
      image.header_matrices.emplace_back(name, m);
    } else if (is_header_attribute(name) && p.type().basetype == OIIO::TypeDesc::FLOAT &&
               p.type().aggregate == OIIO::TypeDesc::VEC3) {
      std::array<float, 3> v{};
      std::memcpy(v.data(), p.data(), sizeof v);
      image.header_vectors.emplace_back(name, v);
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

// The OpenImageIO reader for a file, chosen by its first bytes among the
// four formats drift reads. Left to itself OpenImageIO tries every reader it
// has (TGA, ICO, DDS, ...) on a file the named one refuses: code no one here
// asked for, fed hostile bytes (fuzz_image reached the TGA reader so).
const char* reader_for(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char m[4] = {};
  if (!in.read(reinterpret_cast<char*>(m), 4)) return nullptr;
  if (m[0] == 0x76 && m[1] == 0x2f && m[2] == 0x31 && m[3] == 0x01) return "openexr";
  if (m[0] == 0x89 && m[1] == 'P' && m[2] == 'N' && m[3] == 'G') return "png";
  if (m[0] == 0xff && m[1] == 0xd8 && m[2] == 0xff) return "jpeg";
  if ((m[0] == 'I' && m[1] == 'I' && (m[2] == 42 || m[2] == 43) && m[3] == 0) ||
      (m[0] == 'M' && m[1] == 'M' && m[2] == 0 && (m[3] == 42 || m[3] == 43)))
    return "tiff";
  return nullptr;
}

// OpenImageIO 2.4's OpenEXRCore reader asks its stream for the file's size
// with tell() (OpenImageIO's src/openexr.imageio/exrinput_c.cpp,
// oiio_exr_query_size_func), which is 0 at the start: OpenEXRCore then takes
// the size as unknown and skips every check of
// a declared size against it (a 192-byte file had a 1.8 GB string attribute
// allocated so). This stream answers tell() with the file's size.
class SizedFile final : public OIIO::Filesystem::IOFile {
 public:
  explicit SizedFile(const std::string& name) : IOFile(name, Read) {}
  int64_t tell() override { return static_cast<int64_t>(size()); }
};

struct OpenedImage {
  std::unique_ptr<SizedFile> stream;  // declared first: outlives `in`, which reads it
  std::unique_ptr<OIIO::ImageInput> in;
};

// EXRs are read by OpenImageIO's OpenEXRCore reader (written for fuzzing; its
// header parse is bounded first by validate_exr_header, render/exr_header.cpp).
// It reads drift's own EXRs bit for bit as the C++ reader does, and every
// compression but B44/B44A (values wrong in OpenEXR 3.1.5's core) and
// DWAA/DWAB (not decoded before 3.2): those are refused, naming the fix.
OpenedImage open_image(const std::filesystem::path& path) {
  static const bool core_reader = OIIO::attribute("openexr:core", 1);
  (void)core_reader;
  const char* reader = reader_for(path);
  if (!reader) {
    throw Error("cannot read image " + path.string() +
                ": it is not an EXR, PNG, JPEG or TIFF file (its first bytes say so)");
  }
  const bool exr = std::string(reader) == "openexr";
  OpenedImage opened;
  opened.in = OIIO::ImageInput::create(reader);
  if (exr) {
    validate_exr_header(path);
    opened.stream = std::make_unique<SizedFile>(path.string());
    if (opened.in) opened.in->set_ioproxy(opened.stream.get());
  }
  OIIO::ImageSpec spec;
  if (!opened.in || !opened.in->open(path.string(), spec)) {
    throw Error("cannot read image " + path.string() + ": " +
                oiio_message(opened.in ? opened.in->geterror() : OIIO::geterror()) +
                " (the file may be truncated or corrupt)");
  }
  const std::string compression = spec.get_string_attribute("compression");
  if (exr && (compression.rfind("b44", 0) == 0 || compression.rfind("dwa", 0) == 0)) {
    throw Error("cannot read image " + path.string() + ": its compression '" + compression +
                "' is not read correctly by OpenEXR 3.1's core reader; re-save it with zip "
                "or piz (e.g. oiiotool in.exr --compression zip -o out.exr)");
  }
  return opened;
}

// What reading `spec` takes at its peak: the pixels in the file's own types
// and as float, the float copy made for display images, and for tiled files a
// row of tiles (a tile may be declared far larger than the image).
std::uint64_t bytes_to_read(const OIIO::ImageSpec& spec) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(spec.width) * spec.height;
  const std::uint64_t as_float = pixels * spec.nchannels * sizeof(float);
  const std::uint64_t native = pixels * spec.pixel_bytes(true);
  std::uint64_t tile_row = 0;
  if (spec.tile_width > 0 && spec.tile_height > 0) {
    const std::uint64_t tiles_across =
        (static_cast<std::uint64_t>(spec.width) + spec.tile_width - 1) / spec.tile_width;
    tile_row = tiles_across * spec.tile_width * spec.tile_height *
               std::max<std::uint64_t>(1, spec.tile_depth) *
               std::max<std::uint64_t>(spec.pixel_bytes(true), spec.nchannels * sizeof(float));
  }
  return as_float + std::max(native, as_float) + tile_row;
}

// Pixels as interleaved float. Read in the file's own types and converted
// here: asked for float, OpenImageIO converts through a buffer of at least
// 256 rows (ImageInput::read_scanlines), 256 times what a one-row image
// needs and more than the check above counted.
std::vector<float> read_as_float(OIIO::ImageInput& in, const std::filesystem::path& path) {
  const OIIO::ImageSpec& spec = in.spec();
  const int nc = spec.nchannels;
  const OIIO::stride_t pixel = static_cast<OIIO::stride_t>(spec.pixel_bytes(true));
  std::vector<unsigned char> native(static_cast<std::size_t>(spec.image_bytes(true)));
  if (!in.read_image(0, 0, 0, nc, OIIO::TypeDesc::UNKNOWN, native.data())) {
    throw Error("cannot read the pixels of image " + path.string() + ": " +
                oiio_message(in.geterror()) + " (the file may be truncated or corrupt)");
  }
  std::vector<float> out(static_cast<std::size_t>(spec.width) * spec.height * nc);
  const OIIO::stride_t out_pixel = nc * static_cast<OIIO::stride_t>(sizeof(float));
  std::size_t offset = 0;  // channels may differ in type (EXR): one at a time
  for (int c = 0; c < nc; ++c) {
    const OIIO::TypeDesc type = spec.channelformat(c);
    OIIO::convert_image(1, spec.width, spec.height, 1, native.data() + offset, type, pixel,
                        pixel * spec.width, OIIO::AutoStride, out.data() + c, OIIO::TypeDesc::FLOAT,
                        out_pixel, out_pixel * spec.width, OIIO::AutoStride);
    offset += type.size();
  }
  return out;
}

}  // namespace

Image read_image(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error("image " + path.string() + " does not exist or is not a file; check the path");
  }
  const OpenedImage opened = open_image(path);
  OIIO::ImageInput* in = opened.in.get();
  const OIIO::ImageSpec spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1 || spec.depth > 1 || spec.deep) {
    throw Error("image " + path.string() + " has an unsupported shape (" +
                std::to_string(spec.width) + "x" + std::to_string(spec.height) + ", " +
                std::to_string(spec.nchannels) + " channels)");
  }
  // Sizes are checked before decoding: a small PNG can declare 60000^2 pixels.
  require_memory(bytes_to_read(spec),
                 "image " + path.string() + " (" + std::to_string(spec.width) + "x" +
                     std::to_string(spec.height) + ", " + std::to_string(spec.nchannels) +
                     " channels)",
                 "use a smaller image");
  std::vector<float> raw = read_as_float(*in, path);
  in->close();
  const bool is_float_format = spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                               spec.format.basetype == OIIO::TypeDesc::HALF ||
                               spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  if (std::string(in->format_name()) == "openexr" || is_float_format) {
    return linear_image(spec, std::move(raw));
  }
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
  for (const auto& [name, value] : image.header_texts) spec.attribute(name, value);
  for (const auto& [name, m] : image.header_matrices)
    spec.attribute(name, OIIO::TypeMatrix44, m.data());
  for (const auto& [name, v] : image.header_vectors)
    spec.attribute(name, OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, OIIO::TypeDesc::VEC3), v.data());
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

std::vector<std::uint8_t> display_pixels(const Image& linear, const DisplayTransform& display,
                                         const std::filesystem::path& path) {
  return to_srgb8(linear, resolve_exposure(linear, display), path);
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
