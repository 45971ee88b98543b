// The multi-level heightfield (paper 004, tables 1-3): spans of one column.
#include <gtest/gtest.h>

#include <vector>

#include "terrain/soil/height_spans.h"

namespace drift::soil {
namespace {

struct Column {
  std::vector<float> rho, psi;
  explicit Column(int nz) : rho(nz, 0.0f), psi(nz, 0.0f) {}
  std::vector<HeightSpan> spans() const {
    std::vector<HeightSpan> out(HeightSpans::kMaxSpans);
    out.resize(build_column_spans(rho.data(), psi.data(), static_cast<int>(rho.size()), out.data(),
                                  HeightSpans::kMaxSpans));
    return out;
  }
};

// A span's type and extent (voxels).
void expect_span(const HeightSpan& s, SpanType type, float bottom, float top) {
  EXPECT_EQ(s.type, type);
  EXPECT_FLOAT_EQ(s.bottom, bottom);
  EXPECT_FLOAT_EQ(s.top, top);
}

// Ground pile 2.5 high; a body from 4.3 to 7.6 (partial voxels at both ends);
// 1.75 of soil on it (on the body's 0.6 in voxel 7); falling soil in 12-13.
TEST(HeightSpans, PileBodyPileAndFallingSoil) {
  Column c(16);
  c.rho[0] = c.rho[1] = 1.0f;
  c.rho[2] = 0.5f;
  c.psi[4] = 0.7f;  // body at the top of voxel 4
  c.psi[5] = c.psi[6] = 1.0f;
  c.psi[7] = 0.6f;  // body at the bottom of voxel 7
  c.rho[7] = 0.4f;
  c.rho[8] = 1.0f;
  c.rho[9] = 0.35f;
  c.rho[12] = c.rho[13] = 1.0f;
  c.rho[15] = 0.2f;  // loose falling soil: in no span
  const auto s = c.spans();
  ASSERT_EQ(s.size(), 4u);
  expect_span(s[0], SpanType::Piled, 0.0f, 2.5f);
  EXPECT_FLOAT_EQ(s[0].soil, 2.5f);
  EXPECT_EQ(s[0].top_voxel, 2);
  expect_span(s[1], SpanType::Rigid, 4.3f, 7.6f);
  expect_span(s[2], SpanType::Piled, 7.6f, 9.35f);
  EXPECT_FLOAT_EQ(s[2].soil, 1.75f);
  expect_span(s[3], SpanType::Falling, 12.0f, 14.0f);
}

// Bare ground is a pile of zero height (it can receive sliding soil); a body
// on the floor has no pile under it but a bare one on top.
TEST(HeightSpans, BareGroundAndBodyOnTheFloor) {
  Column bare(8);
  auto s = bare.spans();
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].type, SpanType::Piled);
  EXPECT_FLOAT_EQ(s[0].top, 0.0f);
  Column body(8);
  body.psi[0] = body.psi[1] = 1.0f;
  body.psi[2] = 0.25f;
  s = body.spans();
  ASSERT_EQ(s.size(), 2u);
  expect_span(s[0], SpanType::Rigid, 0.0f, 2.25f);
  expect_span(s[1], SpanType::Piled, 2.25f, 2.25f);
}

}  // namespace
}  // namespace drift::soil
