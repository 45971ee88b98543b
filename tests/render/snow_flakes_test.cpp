// Flakes of thin snow and stuck flakes (render/snow_flakes.h): the covered
// area fraction is the coverage up close, the footprint-filtered value
// averages to it further away and is it exactly far away, the pattern grows
// with the coverage and is a pure function of the world position.
#include "render/snow_flakes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "render/surface.h"
#include "tests/render/snow_layer.h"

namespace drift::render {
namespace {

const Eigen::Vector3f kUp(0, 0, 1);

// Mean and standard deviation of flake_cover over n points drawn uniformly
// in a 200 m square far from the origin (UTM-sized coordinates), on a surface
// of normal `normal` (the square lies in the plane the pattern uses).
struct Moments {
  double mean = 0, std = 0;
};
Moments sample(float coverage, double footprint, const Eigen::Vector3f& normal, int n,
               unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 200.0);
  double s = 0, s2 = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p(746000.0 + u(rng), 4030000.0 + u(rng), 2000.0 + u(rng));
    const double f = flake_cover(p, normal, coverage, footprint);
    s += f, s2 += f * f;
  }
  Moments m;
  m.mean = s / n;
  m.std = std::sqrt(std::max(0.0, s2 / n - m.mean * m.mean));
  return m;
}

const float kCoverages[] = {0.02f, 0.1f, 0.3f, 0.5f, 0.7f, 0.9f, 0.98f};

TEST(SnowFlakes, CloseUpTheCoveredAreaIsTheCoverage) {
  // Point samples (footprint 0): every value is 0 or 1 and the covered
  // fraction is the coverage, on flat ground and on walls facing east and
  // north (overhanging). 10^5 points: sampling error <= 1.6e-3.
  for (const Eigen::Vector3f& normal :
       {kUp, Eigen::Vector3f(0.95f, 0.1f, 0.3f), Eigen::Vector3f(0.1f, -0.9f, -0.4f)}) {
    for (const float c : kCoverages) {
      SCOPED_TRACE(::testing::Message() << "coverage " << c << " normal " << normal.transpose());
      const Moments m = sample(c, 0.0, normal, 100000, 11);
      EXPECT_NEAR(m.mean, c, 0.006);
      // Binary: the standard deviation of a 0/1 variable of mean c.
      EXPECT_NEAR(m.std, std::sqrt(c * (1.0 - c)), 0.01);
    }
  }
}

TEST(SnowFlakes, WithoutClumpingTheBooleanModelCoversExactly) {
  // The flakes alone (no clumps): area fraction 1 - exp(-tau(c)) = c.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 500.0);
  for (const float c : kCoverages) {
    int covered = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) covered += flake_covers(746000.0 + u(rng), u(rng), c, 5) ? 1 : 0;
    EXPECT_NEAR(static_cast<double>(covered) / n, c, 0.005) << "coverage " << c;
  }
}

TEST(SnowFlakes, AtDistanceTheAverageIsTheCoverage) {
  // Footprints from a flake's size to past the clumps: the mean stays the
  // coverage, the spread from point to point falls as the footprint grows
  // (what a pixel would see shimmer is filtered away), and from the clumps'
  // scale on every point is the coverage exactly.
  for (const float c : {0.05f, 0.3f, 0.6f, 0.95f}) {
    SCOPED_TRACE(::testing::Message() << "coverage " << c);
    double previous_std = 1.0;
    for (const double footprint : {0.01, 0.02, 0.03, 0.06, 0.1, 0.2}) {
      const Moments m = sample(c, footprint, kUp, 50000, 17);
      EXPECT_NEAR(m.mean, c, 0.004) << "footprint " << footprint;
      EXPECT_LE(m.std, previous_std + 1e-3) << "footprint " << footprint;
      previous_std = m.std;
    }
    // At 0.2 m only the largest clumps are left, half faded.
    EXPECT_LT(previous_std, 0.35 * std::sqrt(c * (1.0 - c)));
    std::mt19937_64 rng(19);
    std::uniform_real_distribution<double> u(0.0, 200.0);
    for (const double footprint : {kClumpScale, 1.0, 50.0})
      for (int i = 0; i < 1000; ++i) {
        const Eigen::Vector3d p(746000.0 + u(rng), 4030000.0 + u(rng), 2000.0);
        ASSERT_EQ(flake_cover(p, kUp, c, footprint), c) << "footprint " << footprint;
      }
  }
}

// A pixel some 20 m away whose footprint (4 cm) spans a few dozen flakes:
// its true value is the covered fraction of the footprint. 4 samples with the
// footprint filter must be far closer to it than 4 point samples (which
// alias: the flakes would shimmer from pixel to pixel and frame to frame).
TEST(SnowFlakes, FilteredFlakesDoNotAlias) {
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double footprint = 0.04;
  double err_filtered = 0, err_point = 0;
  const int pixels = 200;
  for (int p = 0; p < pixels; ++p) {
    const Eigen::Vector3d corner(746000.0 + 0.37 * p, 4030000.0, 2000.0);
    auto at = [&]() -> Eigen::Vector3d {
      return corner + Eigen::Vector3d(footprint * u(rng), footprint * u(rng), 0);
    };
    double reference = 0, filtered = 0, point = 0;
    for (int i = 0; i < 1024; ++i) reference += flake_cover(at(), kUp, 0.4f, 0.0) / 1024.0;
    for (int i = 0; i < 4; ++i) {
      filtered += flake_cover(at(), kUp, 0.4f, footprint) / 4.0;
      point += flake_cover(at(), kUp, 0.4f, 0.0) / 4.0;
    }
    err_filtered += (filtered - reference) * (filtered - reference) / pixels;
    err_point += (point - reference) * (point - reference) / pixels;
  }
  EXPECT_LT(std::sqrt(err_filtered), 0.5 * std::sqrt(err_point))
      << "rms error filtered " << std::sqrt(err_filtered) << ", point-sampled "
      << std::sqrt(err_point);
}

TEST(SnowFlakes, FlakesDisappearIntoTheirMeanBeyondFourDiameters) {
  // Past four flake diameters only the clumps remain: the value is the
  // smooth local coverage, never a flake's 0 or 1 (unless c is); below two
  // it is a flake's.
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0.0, 50.0);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d p(746000.0 + u(rng), 4030000.0 + u(rng), 2100.0);
    const float v = flake_cover(p, kUp, 0.4f, 8.0 * kFlakeRadius);
    EXPECT_EQ(v, clumped_coverage(p.x(), p.y(), 0.4f, 0x5f1a7e2u, 8.0 * kFlakeRadius));
    EXPECT_GT(v, 0.0f);
    EXPECT_LT(v, 1.0f);
    const float close = flake_cover(p, kUp, 0.4f, 4.0 * kFlakeRadius);
    EXPECT_TRUE(close == 0.0f || close == 1.0f) << close;
  }
}

TEST(SnowFlakes, MoreCoverageOnlyAddsFlakes) {
  // A point covered at coverage c is covered at every larger coverage: the
  // start of a snowfall grows, it does not reshuffle.
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(0.0, 30.0);
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d p(746000.0 + u(rng), 4030000.0 + u(rng), 2100.0);
    float before = 0.0f;
    for (const float c : kCoverages) {
      const float now = flake_cover(p, kUp, c, 0.0);
      ASSERT_GE(now, before) << "coverage " << c;
      before = now;
    }
  }
}

TEST(SnowFlakes, DeterministicAndOrderFree) {
  // A pure function of the position: the same bits whatever the order of
  // evaluation; different planes and positions give different patterns.
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 5000; ++i)
    points.emplace_back(746000.0 + u(rng), 4030000.0 + u(rng), 2000.0 + u(rng));
  std::vector<float> forward, backward(points.size());
  for (const auto& p : points) forward.push_back(flake_cover(p, kUp, 0.35f, 0.002));
  for (std::size_t i = points.size(); i-- > 0;)
    backward[i] = flake_cover(points[i], kUp, 0.35f, 0.002);
  EXPECT_EQ(forward, backward);
  // The wall's pattern is not the ground's seen edge-on.
  int differ = 0;
  for (const auto& p : points) {
    const Eigen::Vector3d swapped(p.x(), p.z(), p.y());
    differ += flake_cover(p, kUp, 0.35f, 0.0) !=
              flake_cover(swapped, Eigen::Vector3f(0, 1, 0), 0.35f, 0.0);
  }
  EXPECT_GT(differ, 1000);
}

// A flat surface 100 m square (local coordinates, origin north-west) of dark
// rock under snow of coverage `cover` and depth `depth`, without sub-cell
// detail so that albedos compare exactly.
// The snow material without its sub-cell detail.
Material plain_snow() {
  Material snow = *material_preset("snow");
  snow.detail = {};
  return snow;
}

TerrainSurface thin_snow(float cover, float depth) {
  TerrainSurface s;
  s.ground = *material_preset("dark_rock");
  s.ground.detail = {};
  s.layers.push_back(testing::snow_layer(
      terrain::HeightField(100, 100, cover, terrain::local_georeference(1.0)),
      terrain::HeightField(100, 100, depth, terrain::local_georeference(1.0)), plain_snow()));
  return s;
}

// The share of 20,000 points up close, uniform (from `seed`) over the inner
// 98 x 98 cells of `s`, that `on_flake` finds on a flake; it stops at the
// first point whose checks fail.
template <class OnFlake>
double flake_share(const TerrainSurface& s, std::uint64_t seed, OnFlake on_flake) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(1.0, 99.0);
  int flakes = 0;
  const int n = 20000;
  for (int i = 0; i < n && !::testing::Test::HasFailure(); ++i) {
    const double x = u(rng), y = -u(rng);
    flakes += on_flake(shade_terrain(s, x, y, kUp, 0.0));
  }
  return static_cast<double>(flakes) / n;
}

TEST(SnowFlakes, ThinSnowShadesAsFlakesUpCloseAndAsTheBlendFarAway) {
  // 9 mm of snow covering 0.3 of the ground (the snowfall's thin snow of
  // 3 cm over 0.3 of it): up close each point is bare rock or a flake whose
  // snow lies 3 cm deep (white), 0.3 of them flakes; far away the blend.
  const TerrainSurface s = thin_snow(0.3f, 0.009f);
  const Eigen::Vector3f flake = layer_albedo(plain_snow().albedo, s.ground.albedo,
                                             s.layers.back().thickness->scattering * 0.03f);
  const double share = flake_share(s, 41, [&](const SurfacePoint& p) {
    const bool on_flake = p.buried == 1.0f;
    EXPECT_TRUE(on_flake || p.buried == 0.0f) << p.buried;
    EXPECT_LT((p.material.albedo - (on_flake ? flake : s.ground.albedo)).norm(), 1e-5f);
    return on_flake;
  });
  EXPECT_NEAR(share, 0.3, 0.015);
  EXPECT_GT(flake.minCoeff(), 0.85f);  // 3 cm of snow over dark rock reads white
  const SurfacePoint far = shade_terrain(s, 50.0, -50.0, kUp, 5.0);
  EXPECT_EQ(far.buried, 0.3f);
  EXPECT_LT((far.material.albedo - mix(s.ground, Material{flake}, 0.3f).albedo).norm(), 1e-5f);
}

TEST(SnowFlakes, SnowPlacedByAMaskShadesAsFlakesToo) {
  // A [[terrain.layer]] of snow whose mask is 0.3: up close each point is
  // bare rock or snow, 0.3 of them snow (the same covered-area = coverage
  // rule as snow cover); far away the even blend, exactly. Without `flakes`
  // the layer stays a film (the blend up close too).
  TerrainSurface s = thin_snow(0.0f, 0.0f);
  s.layers.clear();
  const Material snow = plain_snow();
  MaterialLayer layer;
  layer.material.albedo = snow.albedo;
  layer.mask = terrain::HeightField(100, 100, 0.3f, terrain::local_georeference(1.0));
  layer.flakes = true;
  s.layers.push_back(layer);
  const Eigen::Vector3f film = mix(s.ground, snow, 0.3f).albedo;
  const double share = flake_share(s, 43, [&](const SurfacePoint& p) {
    const Eigen::Vector3f& a = p.material.albedo;
    const bool on_flake = (a - snow.albedo).norm() < 1e-5f;
    EXPECT_TRUE(on_flake || (a - s.ground.albedo).norm() < 1e-5f) << a.transpose();
    return on_flake;
  });
  EXPECT_NEAR(share, 0.3, 0.015);
  EXPECT_LT((shade_terrain(s, 50.0, -50.0, kUp, 5.0).material.albedo - film).norm(), 1e-5f);
  s.layers[0].flakes = false;
  EXPECT_LT((shade_terrain(s, 50.0, -50.0, kUp, 0.0).material.albedo - film).norm(), 1e-5f);
}

TEST(SnowFlakes, StuckFlakesOnAWallWithoutDepthReadWhite) {
  // Adhesion: coverage without depth. The flakes are a flake's depth of
  // snow (kFlakeDepth), not the bare rock the zero depth would give.
  const TerrainSurface s = thin_snow(0.5f, 0.0f);
  const Eigen::Vector3f wall(0.97f, 0.0f, 0.243f);
  float brightest = 0.0f;
  for (int i = 0; i < 400; ++i) {
    const SurfacePoint p = shade_terrain(s, 10.0 + 0.0037 * i, -50.0, wall, 0.0,
                                         Relief{0.0f, 76.0f, 2000.0 + 0.0051 * i});
    brightest = std::max(brightest, p.material.albedo.minCoeff());
  }
  EXPECT_GT(brightest, 0.7f);
}

// Mean and standard deviation of flake_cover on flat ground seen along `ray`.
Moments sample_along(float coverage, double footprint, const Eigen::Vector3f& ray, int n) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0.0, 200.0);
  double s = 0, s2 = 0;
  for (int i = 0; i < n; ++i) {
    const double f =
        flake_cover({746000.0 + u(rng), 4030000.0 + u(rng), 2000.0}, kUp, coverage, footprint, ray);
    s += f, s2 += f * f;
  }
  Moments m;
  m.mean = s / n;
  m.std = std::sqrt(std::max(0.0, s2 / n - m.mean * m.mean));
  return m;
}

TEST(SnowFlakes, GrazingFootprintsStretchAlongTheRay) {
  // A ray 3 degrees above flat ground: a footprint 3 mm across is 5.7 cm (19
  // times) long on the ground. Filtered as a round 3 mm it would point-sample
  // the flakes (0 or 1: shimmer from pixel to pixel and frame to frame);
  // stretched along the ray it averages the flakes it spans, keeping the mean.
  const float elevation = 3.0f * static_cast<float>(std::numbers::pi / 180.0);
  const Eigen::Vector3f grazing(std::cos(elevation), 0.0f, -std::sin(elevation));
  for (const float c : {0.1f, 0.3f, 0.7f}) {
    SCOPED_TRACE(::testing::Message() << "coverage " << c);
    const double binary = std::sqrt(c * (1.0 - c));
    const Moments round = sample_along(c, 0.003, Eigen::Vector3f::Zero(), 40000);
    const Moments stretched = sample_along(c, 0.003, grazing, 40000);
    std::printf("coverage %.1f: spread %.3f stretched, %.3f round\n", c, stretched.std, round.std);
    EXPECT_NEAR(round.std, binary, 0.01);  // what the round footprint does
    EXPECT_NEAR(stretched.mean, c, 0.01);
    EXPECT_LT(stretched.std, 0.6 * binary);
    // Far away (a footprint 0.4 m across, 7.6 m along): the coverage exactly.
    const Moments far = sample_along(c, 0.4, grazing, 2000);
    EXPECT_NEAR(far.mean, c, 1e-6);
    EXPECT_LT(far.std, 1e-6);
  }
  // Seen head-on the footprint is round: the same value as without a ray.
  const Eigen::Vector3d p(746001.3, 4030002.7, 2000.0);
  for (const double footprint : {0.0, 0.003, 0.02})
    EXPECT_EQ(flake_cover(p, kUp, 0.4f, footprint, Eigen::Vector3f(0, 0, -1)),
              flake_cover(p, kUp, 0.4f, footprint));
}

TEST(SnowFlakes, NoneAndFullCoverage) {
  const Eigen::Vector3d p(746001.0, 4030002.0, 2000.0);
  EXPECT_EQ(flake_cover(p, kUp, 0.0f, 0.0), 0.0f);
  EXPECT_EQ(flake_cover(p, kUp, -0.5f, 0.0), 0.0f);
  EXPECT_EQ(flake_cover(p, kUp, 1.0f, 0.0), 1.0f);
  EXPECT_EQ(flake_cover(p, kUp, NAN, 0.0), 0.0f);
}

}  // namespace
}  // namespace drift::render
