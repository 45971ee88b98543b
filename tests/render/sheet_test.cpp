#include <gtest/gtest.h>

#include "render/contact_sheet.h"
#include "terrain/error.h"

namespace drift::render {
namespace {

TEST(ContactSheet, SizeFollowsTheLayout) {
  std::vector<Image> images(5, Image(30, 20, {"R", "G", "B"}, 0.5f));
  images[2] = Image(24, 26, {"R", "G", "B"}, 0.2f);  // cell = 30 x 26
  ContactSheetOptions o;
  o.columns = 3;
  o.padding = 4;
  o.font_size = 10;
  const Image plain = contact_sheet(images, o);
  EXPECT_EQ(plain.width, 3 * (30 + 4) + 4);
  EXPECT_EQ(plain.height, 2 * (26 + 4) + 4);
  o.labels = {"a", "b", "c", "d", "e"};
  o.title = "sweep";
  const Image labelled = contact_sheet(images, o);
  EXPECT_EQ(labelled.width, plain.width);
  EXPECT_EQ(labelled.height, (15 + 8) + 2 * (26 + 10 + 4 + 4) + 4);
}

TEST(ContactSheet, LabelsChangePixels) {
  if (default_font().empty()) GTEST_SKIP() << "no DejaVu font installed";
  std::vector<Image> images(2, Image(40, 20, {"R", "G", "B"}, 0.3f));
  ContactSheetOptions o;
  o.labels = {"", ""};  // empty labels: no band and no text
  const Image none = contact_sheet(images, o);
  o.labels = {"x", "y"};
  const Image with = contact_sheet(images, o);
  o.labels = {"x", "z"};
  const Image other = contact_sheet(images, o);
  ASSERT_EQ(with.pixels.size(), other.pixels.size());
  EXPECT_NE(with.pixels, other.pixels);
  int bright = 0;
  for (float v : with.pixels) bright += v > 0.5f;  // text is white, cells 0.3, background 0.05
  EXPECT_GT(bright, 10) << "pixels lit by the labels";
  EXPECT_LT(none.height, with.height);
  // The images themselves are in place (first cell starts at padding).
  EXPECT_FLOAT_EQ(with.at(8, 8, 0), 0.3f);
}

TEST(ContactSheet, BadOptionsAreErrors) {
  std::vector<Image> images(2, Image(4, 4, {"R", "G", "B"}));
  ContactSheetOptions o;
  o.labels = {"one"};
  EXPECT_THROW(contact_sheet(images, o), Error);
  o.labels = {"one", "two"};
  o.font = "/no/such/font.ttf";
  EXPECT_THROW(contact_sheet(images, o), Error);
  EXPECT_THROW(contact_sheet({}, {}), Error);
}

}  // namespace
}  // namespace drift::render
