// 16-bit heights (issue 36 item 1; render/height_field.h, QuantisedHeights;
// drift render --height-bits 16): each vertex within half a step of its
// owning block's range, a height field over them tracing exactly the
// surface of its decoded heights, and a frame within a stated tolerance of
// the float heights' frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "render/camera_setup.h"
#include "render/height_field.h"
#include "render/renderer.h"
#include "render/terrain_scene.h"
#include "tests/render/relief_fixture.h"
#include "tests/render/render_fixtures.h"

using namespace drift::render;
using drift::terrain::HeightField;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Relief of w x h vertices, 2 m apart: long slopes, rough patches, flat
// blocks (range 0), cliffs and spikes, heights up to ~1,500 m so that a
// block's step and a float's ulp are both visible.
HeightGrid relief(int w, int h) {
  HeightGrid g;
  g.width = w, g.height = h;
  g.x0 = -w, g.y0 = h;
  g.dx = g.dy = 2.0f;
  g.z.resize(static_cast<std::size_t>(w) * h);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> noise(-1.0f, 1.0f);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      g.z[static_cast<std::size_t>(r) * w + c] =
          drift::testing::quantised_relief(c, r, w, noise(rng), /*flat_corner=*/true);
  return g;
}

float ulp(float x) { return std::nextafter(std::fabs(x), kInf) - std::fabs(x); }

}  // namespace

// The bound docs/rendering.md states: half a step of the range of the block
// owning the vertex (its 16 x 16 vertices; the last row and column belong to
// the last block) plus half an ulp of the decoded float. Computed here from
// the heights alone, not from the quantiser's ranges.
TEST(QuantisedHeights, ErrorIsWithinHalfAStepOfEachBlock) {
  for (const auto& [w, h] : {std::pair{150, 131}, std::pair{33, 17}, std::pair{2, 2}}) {
    const HeightGrid g = relief(w, h);
    const QuantisedHeights q(g);
    const int bx = std::max(1, (w - 2) / 16 + 1), by = std::max(1, (h - 2) / 16 + 1);
    std::vector<float> lo(static_cast<std::size_t>(bx) * by, kInf), hi(lo.size(), -kInf);
    const auto owner = [&](int c, int r) {
      return static_cast<std::size_t>(std::min(r / 16, by - 1)) * bx + std::min(c / 16, bx - 1);
    };
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        const std::size_t b = owner(c, r);
        lo[b] = std::min(lo[b], g.at(c, r)), hi[b] = std::max(hi[b], g.at(c, r));
      }
    double worst = 0.0;  // the largest error over its bound
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        const std::size_t b = owner(c, r);
        const float decoded = q.at(c, r);
        const double bound = (static_cast<double>(hi[b]) - lo[b]) / 65535.0 / 2.0;
        const double error = std::fabs(static_cast<double>(decoded) - g.at(c, r));
        ASSERT_LE(error, bound * (1 + 1e-6) + 0.5 * ulp(decoded))
            << "vertex " << c << ", " << r << " of " << w << " x " << h;
        if (bound > 0) worst = std::max(worst, error / bound);
        if (hi[b] == lo[b]) {
          EXPECT_EQ(decoded, g.at(c, r));  // a flat block is exact
        }
      }
    // The bound is reached, not loose by orders of magnitude.
    if (w > 100) {
      EXPECT_GT(worst, 0.9);
    }
  }
  const HeightGrid g = relief(150, 131);
  EXPECT_EQ(QuantisedHeights(g).bytes(), g.z.size() * 2 + 10 * 9 * 8);
}

// The height field over 16-bit heights meets exactly the surface of its
// decoded heights (the float height field over them): the same hit, cell,
// triangle and normal, bit for bit, for rays of every kind. A vertex on an
// edge is decoded with its owning block's range whichever block reads it.
TEST(QuantisedHeights, HeightFieldTracesItsDecodedHeightsExactly) {
  const HeightGrid g = relief(150, 131);
  // The frame keeps the float heights: a field that read them instead of
  // its 16-bit ones would meet another surface than the reference.
  const HeightGrid& frame = g;
  QuantisedHeights q(g);
  HeightGrid decoded = g;
  for (int r = 0; r < g.height; ++r)
    for (int c = 0; c < g.width; ++c)
      decoded.z[static_cast<std::size_t>(r) * g.width + c] = q.at(c, r);
  const HeightFieldBlocks sixteen(frame, std::move(q));
  const HeightFieldBlocks reference(decoded);
  ASSERT_TRUE(sixteen.quantised());
  ASSERT_EQ(sixteen.block_count(), reference.block_count());
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    // From above any way down, grazing, and aimed along block edges.
    Eigen::Vector3f o(u(rng) * 160.0f, u(rng) * 140.0f, 1600.0f + 200.0f * u(rng));
    Eigen::Vector3f d(u(rng), u(rng), -2.0f - std::fabs(u(rng)));  // 300 m wide, 1,400 m high
    if (i % 3 == 1) o.x() = g.x(16 * (1 + i % 8)), d.x() = 0.0f;   // along a block column
    if (i % 3 == 2) o.z() = 1000.0f, d.z() = -0.02f * std::fabs(u(rng));
    const HeightRay ray(o, d.normalized());
    float ta = kInf, tb = kInf;
    HeightHit a, b;
    bool ha = false, hb = false;
    for (unsigned k = 0; k < sixteen.block_count(); ++k) {
      ha |= sixteen.intersect(k, ray, 0.0f, ta, a);
      hb |= reference.intersect(k, ray, 0.0f, tb, b);
    }
    ASSERT_EQ(ha, hb) << "ray " << i;
    ASSERT_EQ(ta, tb) << "ray " << i;
    if (!ha) continue;
    ++hits;
    EXPECT_EQ(a.cell_x, b.cell_x);
    EXPECT_EQ(a.cell_row, b.cell_row);
    EXPECT_EQ(a.triangle, b.triangle);
    EXPECT_EQ(a.ng, b.ng);
    EXPECT_EQ(sixteen.height(a.cell_x, a.cell_row), decoded.at(a.cell_x, a.cell_row));
  }
  EXPECT_GT(hits, 1000);
}

// Through the scene: vertical rays meet the 16-bit ground within the bound
// of the float ground, the scene holds about 3 B a cell instead of 5, and a
// frame is within 0.5 % (mean absolute difference over the mean) of the
// float heights' frame.
TEST(QuantisedHeights, SceneAndFrameAreWithinTheBoundOfFloatHeights) {
  const int w = 150, h = 131;
  const HeightGrid g = relief(w, h);
  HeightField dem(w, h, 0.0f, drift::terrain::local_georeference(2.0));
  dem.geo().geotransform[0] = 500000.0;
  dem.geo().geotransform[3] = 5200000.0;
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) dem(c, r) = g.at(c, r);
  SceneInput in;
  in.terrain = dem;
  in.surround.reach = 0.0;
  in.sun.elevation_deg = 20.0;
  const TerrainScene floats(in, TerrainGeometry::HeightField);
  const TerrainScene sixteen(in, TerrainGeometry::HeightField16);
  EXPECT_LT(sixteen.terrain_bytes(), dem.size() * 3);
  EXPECT_GT(floats.terrain_bytes(), dem.size() * 4);
  // The largest step of any block: a vertex moves at most half of it, a
  // point on a triangle (a convex combination) too.
  float largest = 0.0f;
  for (int by = 0; by * 16 < h - 1; ++by)
    for (int bx = 0; bx * 16 < w - 1; ++bx) {
      float lo = kInf, hi = -kInf;
      for (int r = by * 16; r < std::min(by * 16 + 16, h); ++r)
        for (int c = bx * 16; c < std::min(bx * 16 + 16, w); ++c)
          lo = std::min(lo, g.at(c, r)), hi = std::max(hi, g.at(c, r));
      largest = std::max(largest, hi - lo);
    }
  const float bound = largest / 65535.0f / 2.0f + 4 * ulp(1600.0f);
  float worst = 0.0f;
  const Eigen::Vector2f inside = floats.extent() / 2 * 0.99f;
  drift::testing::random_rays(2000, 9, inside, 2000.0f, 0.0f, [&](int i, auto o, auto d) {
    const float a = floats.hit_distance(o, d), b = sixteen.hit_distance(o, d);
    ASSERT_TRUE(std::isfinite(a) && std::isfinite(b)) << "ray " << i;
    worst = std::max(worst, std::fabs(a - b));
    ASSERT_LE(std::fabs(a - b), bound) << "ray " << i;
    EXPECT_NEAR(floats.height_at(o.x(), o.y()), sixteen.height_at(o.x(), o.y()), bound);
  });
  EXPECT_GT(worst, 0.0f);  // the heights did move
  const RenderSettings rs = drift::testing::frame_settings(64, 36, 2);
  const Image a = render_image(floats, in, default_camera(floats), rs);
  const Image b = render_image(sixteen, in, default_camera(sixteen), rs);
  double diff = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    diff += std::fabs(a.pixels[i] - b.pixels[i]);
    sum += std::fabs(a.pixels[i]);
  }
  EXPECT_LT(diff / sum, 5e-3) << "mean difference " << diff / sum;
}
