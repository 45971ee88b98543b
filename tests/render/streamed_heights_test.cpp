// The DEM read strip by strip into 16-bit heights (issue 36 item 1;
// render/streamed_heights.h; drift render --height-bits 16 in core): the same
// codes, ranges, extremes and sums as quantising the whole DEM read as floats
// at any strip height, and a scene that traces and renders bit for bit as the
// scene of the whole DEM with TerrainGeometry::HeightField16 (ring beyond the
// edge, nodata and vertical exaggeration included).
#include "render/streamed_heights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "render/camera_setup.h"
#include "render/height_field.h"
#include "render/renderer.h"
#include "render/terrain_scene.h"
#include "terrain/error.h"
#include "terrain/raster_io.h"
#include "tests/render/relief_fixture.h"
#include "tests/render/render_fixtures.h"
#include "tests/test_files.h"

using namespace drift::render;
using drift::terrain::HeightField;

namespace {

constexpr float kExaggeration = 1.5f;

// 301 x 545 cells at 2 m: slopes, rough ground, a cliff, spikes, a nodata
// hole; 545 rows make 34 block rows, the last owning 17 vertex rows.
HeightField dem() {
  constexpr int w = 301;
  return drift::testing::noisy_relief(w, 545, 2.0, 5, [](int c, int r, float noise) {
    if (c > 200 && c < 230 && r > 250 && r < 270) return NAN;  // nodata: the lowest height
    return drift::testing::quantised_relief(c, r, w, noise, /*flat_corner=*/false);
  });
}

std::filesystem::path written(const HeightField& d) {
  const std::filesystem::path p = drift::testing::test_dir("drift_streamed_heights") / "dem.tif";
  drift::terrain::write_geotiff(d, p);
  return p;
}

// The local heights TerrainScene converts a DEM held in core to.
HeightGrid local(const HeightField& d, float k) {
  float lo = INFINITY;
  for (const float v : d.values())
    if (!std::isnan(v)) lo = std::min(lo, v);
  const float z0 = static_cast<float>(static_cast<double>(lo) * static_cast<double>(k));
  HeightGrid g;
  g.width = d.width(), g.height = d.height();
  g.z.resize(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    const float h = std::isnan(d.values()[i]) ? lo : d.values()[i];
    g.z[i] = h * k - z0;
  }
  return g;
}

}  // namespace

TEST(StreamedHeights, CodesRangesExtremesAndSumsMatchTheWholeDemAtAnyStrip) {
  const HeightField d = dem();
  const std::filesystem::path file = written(d);
  const HeightGrid g = local(d, kExaggeration);
  const QuantisedHeights whole(g);
  // The whole grid's extremes (the first in row-major order) and the sums
  // of its decoded heights, row-major.
  std::size_t hi = 0, lo = 0;
  double sum = 0.0, squares = 0.0;
  for (std::size_t i = 0; i < g.z.size(); ++i) {
    if (g.z[i] > g.z[hi]) hi = i;
    if (g.z[i] < g.z[lo]) lo = i;
    const float z = whole.at(static_cast<int>(i % g.width), static_cast<int>(i / g.width));
    sum += z, squares += double(z) * z;
  }
  for (const int strip : {16, 48, 256, 4096}) {
    SCOPED_TRACE(strip);
    const StreamedHeights s = read_streamed_heights(file, kExaggeration, strip);
    ASSERT_EQ(s.heights.width(), g.width);
    ASSERT_EQ(s.heights.height(), g.height);
    for (int r = 0; r < g.height; ++r)
      for (int c = 0; c < g.width; ++c) {
        ASSERT_EQ(s.heights.code(c, r), whole.code(c, r)) << c << ", " << r;
        ASSERT_EQ(s.heights.at(c, r), whole.at(c, r)) << c << ", " << r;
      }
    EXPECT_EQ(s.heights.bytes(), whole.bytes());
    EXPECT_EQ(s.sum, sum);
    EXPECT_EQ(s.sum_squares, squares);
    EXPECT_EQ(s.highest.z(), g.z[hi]);
    EXPECT_EQ(s.lowest.z(), g.z[lo]);
    EXPECT_EQ(s.highest.x(), s.frame.x(static_cast<int>(hi % g.width)));
    EXPECT_EQ(s.highest.y(), s.frame.y(static_cast<int>(hi / g.width)));
    EXPECT_EQ(s.lowest.x(), s.frame.x(static_cast<int>(lo % g.width)));
  }
}

TEST(StreamedHeights, SceneTracesAndRendersAsTheWholeDemBitForBit) {
  const HeightField d = dem();
  const std::filesystem::path file = written(d);
  SceneInput in;
  in.terrain = drift::terrain::read_raster(file);
  in.vertical_exaggeration = kExaggeration;
  in.surround.reach = 3000.0;  // the ring, built from the decoded edge
  in.sun.elevation_deg = 20.0;
  const TerrainScene whole(in, TerrainGeometry::HeightField16);
  SceneInput none = in;
  none.terrain = HeightField();  // the streamed scene must not read it
  const TerrainScene streamed(none, file);
  EXPECT_EQ(streamed.highest_point(), whole.highest_point());
  EXPECT_EQ(streamed.lowest_point(), whole.lowest_point());
  EXPECT_EQ(streamed.origin(), whole.origin());
  EXPECT_EQ(streamed.terrain_bytes(), whole.terrain_bytes());
  EXPECT_EQ(streamed.surround_reach(), whole.surround_reach());
  EXPECT_EQ(streamed.bottom(), whole.bottom());
  EXPECT_EQ(streamed.top(), whole.top());
  const Eigen::Vector2f half = whole.extent() / 2;
  int ring = 0;
  // Rays over the DEM and over the ring beyond its edge, oblique.
  const Eigen::Vector2f spread(half.x() * 3.0f, half.y() * 2.0f);
  drift::testing::random_rays(3000, 3, spread, 2500.0f, 0.5f, [&](int i, auto o, auto dir) {
    Eigen::Vector3f na, nb;
    const float a = whole.hit_distance(o, dir, &na), b = streamed.hit_distance(o, dir, &nb);
    ASSERT_EQ(a, b) << "ray " << i;
    if (std::isfinite(a)) {
      ASSERT_EQ(na, nb) << "ray " << i;
    }
    const Eigen::Vector3f p = o + a * dir;
    if (std::isfinite(a) && (std::fabs(p.x()) > half.x() || std::fabs(p.y()) > half.y())) ++ring;
  });
  EXPECT_GT(ring, 300) << "rays must meet the ring beyond the edge too";
  const RenderSettings rs = drift::testing::frame_settings(64, 36, 2);
  const Image a = render_image(whole, in, default_camera(whole), rs);
  const Image b = render_image(streamed, none, default_camera(streamed), rs);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(a.pixels[0])),
            0);
}

TEST(StreamedHeights, RefusesWhatItCannotRead) {
  const std::filesystem::path dir = drift::testing::test_dir("drift_streamed_refused");
  HeightField nodata(4, 4, NAN, drift::terrain::local_georeference(1.0));
  drift::terrain::write_geotiff(nodata, dir / "nodata.tif");
  try {
    read_streamed_heights(dir / "nodata.tif", 1.0f);
    FAIL() << "an all-nodata raster was read";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("nodata.tif"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("all nodata"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_streamed_heights(dir / "missing.tif", 1.0f), drift::Error);
}
