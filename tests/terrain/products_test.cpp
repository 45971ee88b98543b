// The declared product forms (terrain/products.h): a snowy-objects mesh is
// checked against its form before it is split, and a mesh that lacks an
// attribute is an error naming the file, the attribute and the writer.
#include "terrain/products.h"

#include <gtest/gtest.h>

#include <string>

#include "terrain/error.h"

using namespace drift::terrain;

namespace {

// Two objects (a triangle each) with every attribute of kSnowyObjects.
Mesh snowy_pair() {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 1}, {6, 5, 1}, {5, 6, 1}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  for (const char* name : products::kSnowyObjects.attributes)
    m.vertex_attributes.emplace_back(name, std::vector<float>(6, 0.5f));
  for (auto& [name, values] : m.vertex_attributes)
    if (name == products::kObjectIndex) values = {0, 0, 0, 1, 1, 1};
  return m;
}

std::string error_of(const Mesh& m) {
  try {
    products::split_objects(m, products::kSnowyObjects, "roof.ply");
  } catch (const drift::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Products, SnowyObjectsSplitByObjectKeepingTheirAttributes) {
  const auto parts = products::split_objects(snowy_pair(), products::kSnowyObjects, "roof.ply");
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[1].vertex_count(), 3u);
  ASSERT_NE(parts[1].attribute(products::kSnowCoverage), nullptr);
  EXPECT_FLOAT_EQ((*parts[1].attribute(products::kSnowCoverage))[2], 0.5f);
}

TEST(Products, AMeshWithoutAnAttributeOfItsFormIsAnErrorNamingFileAttributeAndWriter) {
  for (const char* missing : products::kSnowyObjects.attributes) {
    Mesh m = snowy_pair();
    std::erase_if(m.vertex_attributes, [&](const auto& a) { return a.first == missing; });
    const std::string message = error_of(m);
    EXPECT_NE(message.find("roof.ply"), std::string::npos) << message;
    EXPECT_NE(message.find(std::string("'") + missing + "'"), std::string::npos) << message;
    EXPECT_NE(message.find("drift snow fall --mesh-out"), std::string::npos) << message;
  }
  Mesh short_column = snowy_pair();
  short_column.vertex_attributes[0].second.pop_back();
  EXPECT_NE(error_of(short_column).find("5 '"), std::string::npos) << error_of(short_column);
  EXPECT_EQ(error_of(snowy_pair()), "");
}
