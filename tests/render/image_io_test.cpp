#include "render/image_io.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "terrain/error.h"

namespace drift::render {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  fs::path d = fs::path(DRIFT_BINARY_DIR) / "test_tmp" / "image_io";
  fs::create_directories(d);
  return d;
}

Image random_image(int w, int h, std::vector<std::string> channels, float lo, float hi) {
  Image im(w, h, std::move(channels));
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(lo, hi);
  for (float& v : im.pixels) v = u(rng);
  return im;
}

TEST(ImageIo, ExrRoundTripIsBitExactWithAllChannels) {
  Image im = random_image(37, 23, {"R", "G", "B", "A", "depth", "albedo.R"}, -5.0f, 1e4f);
  im.at(3, 4, 4) = 1e-30f;  // denormal-ish and extremes survive float32 storage
  const fs::path p = temp_dir() / "round.exr";
  write_exr(im, p);
  const Image back = read_image(p);
  ASSERT_EQ(back.width, 37);
  ASSERT_EQ(back.height, 23);
  ASSERT_EQ(back.channel_count(), im.channel_count());
  for (const auto& c : im.channels) EXPECT_GE(back.channel_index(c), 0) << c;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x)
      for (int c = 0; c < im.channel_count(); ++c) {
        const int bc = back.channel_index(im.channels[c]);
        const float va = im.at(x, y, c), vb = back.at(x, y, bc);
        ASSERT_EQ(std::memcmp(&va, &vb, 4), 0) << im.channels[c] << " at " << x << "," << y << ": "
                                               << im.at(x, y, c) << " vs " << back.at(x, y, bc);
      }
}

TEST(ImageIo, TheSameImageWritesTheSameBytes) {
  // No clock in the file: OpenImageIO's default capDate differs from one
  // second to the next. Two writes within one second match anyway, so the
  // date itself is checked too.
  const Image im = random_image(8, 8, {"R", "G", "B"}, 0.0f, 1.0f);
  const fs::path a = temp_dir() / "same_a.exr", b = temp_dir() / "same_b.exr";
  write_exr(im, a);
  write_exr(im, b);
  auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(bytes(a), bytes(b));
  const std::string file = bytes(a);
  const std::size_t at = file.find("capDate");
  if (at != std::string::npos) {
    // name, type "string", a 4-byte length: zero.
    const std::size_t length = at + std::strlen("capDate") + 1 + std::strlen("string") + 1;
    ASSERT_LT(length + 4, file.size());
    EXPECT_EQ(file.compare(length, 4, std::string(4, '\0')), 0) << "a date in the file";
  }
}

TEST(ImageIo, PngRoundTripWithinOneStep) {
  const Image im = random_image(31, 17, {"R", "G", "B"}, 0.0f, 1.0f);
  const fs::path p = temp_dir() / "round.png";
  const DisplayTransform clamp{0.0, ToneCurve::Clamp};
  write_png(im, p, clamp);
  const Image back = read_image(p);
  ASSERT_EQ(back.width, 31);
  ASSERT_EQ(back.channels, (std::vector<std::string>{"R", "G", "B"}));
  double worst = 0;
  for (std::size_t i = 0; i < im.pixels.size(); ++i) {
    const double d = std::abs(srgb_encode(im.pixels[i]) - srgb_encode(back.pixels[i])) * 255.0;
    worst = std::max(worst, d);
  }
  EXPECT_LE(worst, 0.5 + 1e-3) << "largest encoded difference in 8-bit steps";
  // decode -> encode of what was read is exact: writing it again gives the same bytes.
  const fs::path p2 = temp_dir() / "round2.png";
  write_png(back, p2, clamp);
  const Image again = read_image(p2);
  EXPECT_EQ(again.pixels, back.pixels);
}

TEST(ImageIo, PngAppliesExposureAndCurve) {
  Image im(2, 1, {"R", "G", "B"}, 0.25f);
  const fs::path p = temp_dir() / "exposure.png";
  write_png(im, p, DisplayTransform{1.0, ToneCurve::Clamp});
  const Image back = read_image(p);
  EXPECT_NEAR(back.at(0, 0, 0), 0.5f, 0.5f / 255.0f * 2.0f);  // +1 EV doubles 0.25
}

TEST(ImageIo, WriteImageChoosesByExtension) {
  const Image im(4, 4, {"R", "G", "B"}, 0.5f);
  write_image(im, temp_dir() / "upper.EXR");
  write_image(im, temp_dir() / "upper.PNG");
  EXPECT_EQ(read_image(temp_dir() / "upper.EXR").at(1, 1, 1), 0.5f);
  try {
    write_image(im, temp_dir() / "frame.jpg");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("frame.jpg"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(temp_dir() / "frame.jpg"));
}

TEST(ImageIo, FailedWriteLeavesNothing) {
  const Image im(4, 4, {"R", "G", "B"}, 0.5f);
  EXPECT_THROW(write_exr(im, temp_dir() / "no_such_dir" / "x.exr"), Error);
  EXPECT_FALSE(fs::exists(temp_dir() / "no_such_dir"));
}

void expect_read_error(const fs::path& p) {
  try {
    read_image(p);
    FAIL() << "expected an error reading " << p;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos) << e.what();
  }
}

void truncate_copy(const fs::path& from, const fs::path& to, double fraction) {
  std::ifstream in(from, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::ofstream(to, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size() * fraction));
}

TEST(ImageIo, BadFilesAreErrorsNamingTheFile) {
  expect_read_error(temp_dir() / "missing.exr");
  const fs::path text = temp_dir() / "not_an_image.png";
  std::ofstream(text) << "hello, this is not a PNG\n";
  expect_read_error(text);

  const Image im = random_image(64, 64, {"R", "G", "B"}, 0.0f, 1.0f);
  write_png(im, temp_dir() / "whole.png");
  truncate_copy(temp_dir() / "whole.png", temp_dir() / "truncated.png", 0.5);
  expect_read_error(temp_dir() / "truncated.png");
  write_exr(im, temp_dir() / "whole.exr");
  truncate_copy(temp_dir() / "whole.exr", temp_dir() / "truncated.exr", 0.5);
  expect_read_error(temp_dir() / "truncated.exr");
}

// An EXR header attribute declaring more bytes than the file holds is refused
// before OpenEXR allocates it (a 973-byte file had 1.9 GB allocated; found by
// fuzz_image, kept in tests/fuzz/regressions/image/;
// tests/fuzz/reader_allocation_test.cpp measures the allocations themselves).
TEST(ImageIo, ExrAttributeLargerThanTheFileIsRefusedBeforeAllocating) {
  const fs::path file = temp_dir() / "huge_attribute.exr";
  std::ofstream out(file, std::ios::binary);
  const unsigned char version[8] = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
  out.write(reinterpret_cast<const char*>(version), 8);
  const char name_and_type[] = "capDate\0string";  // two null-terminated strings
  out.write(name_and_type, sizeof name_and_type);
  const std::int32_t size = 0x7ffffff0;
  out.write(reinterpret_cast<const char*>(&size), 4);
  out << "2026:11:24 20:26:15";
  out.close();
  try {
    read_image(file);
    ADD_FAILURE() << "read";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'capDate', type 'string': Invalid size 2147483632"), std::string::npos) << m;
    EXPECT_NE(m.find(file.string()), std::string::npos) << m;
  }
  // A name longer than OpenEXR's 31 characters is refused as such.
  const fs::path cut = temp_dir() / "long_name.exr";
  std::ofstream cut_out(cut, std::ios::binary);
  cut_out.write(reinterpret_cast<const char*>(version), 8);
  cut_out << std::string(32, 'a') << 'b' << '\0';
  cut_out.write(reinterpret_cast<const char*>(&size), 4);
  cut_out << "0123456789";
  cut_out.close();
  expect_read_error(cut);
}

// Only EXR, PNG, JPEG and TIFF are read, chosen by the file's first bytes:
// OpenImageIO would otherwise try each of its readers on a file (fuzz_image
// reached its TGA reader; an EXR its reader refused was opened as a 64x64
// image by another).
TEST(ImageIo, OnlyExrPngJpegAndTiffAreRead) {
  const Image im(4, 4, {"R", "G", "B"}, 0.5f);
  write_png(im, temp_dir() / "real.png");
  fs::copy_file(temp_dir() / "real.png", temp_dir() / "png_named.exr",
                fs::copy_options::overwrite_existing);
  EXPECT_EQ(read_image(temp_dir() / "png_named.exr").pixels,
            read_image(temp_dir() / "real.png").pixels);
  const fs::path tga = temp_dir() / "frame.tga";
  auto out = OIIO::ImageOutput::create(tga.string());
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeDesc::UINT8);
  const std::vector<unsigned char> grey(48, 128);
  ASSERT_TRUE(out->open(tga.string(), spec) &&
              out->write_image(OIIO::TypeDesc::UINT8, grey.data()));
  out->close();
  try {
    read_image(tga);
    ADD_FAILURE() << "read a TGA";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is not an EXR, PNG, JPEG or TIFF file"),
              std::string::npos)
        << e.what();
  }
}

// OpenEXR 3.1.5's core reader gets B44 values wrong and cannot decode DWAA:
// such files are refused naming the fix, never read as wrong pixels.
TEST(ImageIo, LossyExrCompressionsAreRefusedNamingTheFix) {
  for (const char* compression : {"b44", "dwaa"}) {
    const fs::path file = temp_dir() / (std::string(compression) + ".exr");
    auto out = OIIO::ImageOutput::create(file.string());
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(16, 16, 3, OIIO::TypeDesc::HALF);
    spec.attribute("compression", compression);
    const std::vector<float> pixels(16 * 16 * 3, 0.5f);
    ASSERT_TRUE(out->open(file.string(), spec) &&
                out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
    out->close();
    try {
      read_image(file);
      ADD_FAILURE() << "read " << compression;
    } catch (const Error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(std::string("its compression '") + compression), std::string::npos) << m;
      EXPECT_NE(m.find("re-save it with zip"), std::string::npos) << m;
    }
  }
}

}  // namespace
}  // namespace drift::render
