#include "render/ground_detail.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "render/bsdf.h"
#include "render/color.h"
#include "render/land_form.h"
#include "render/material.h"
#include "render/procedural_noise.h"
#include "terrain/error.h"

namespace drift::render {
namespace {

GroundDetail rock_detail() { return material_preset("dark_rock")->detail; }

TEST(ProceduralNoise, MomentsMatchTheConstants) {
  // The constants that normalise the octaves are the noise's own moments.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-5e4, 5e4);
  double s = 0, s2 = 0, g2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const NoiseSample v = value_noise(u(rng), u(rng), 3);
    s += v.value, s2 += v.value * v.value, g2 += v.gradient.squaredNorm();
  }
  EXPECT_NEAR(s / n, 0.0, 0.01);
  EXPECT_NEAR(std::sqrt(s2 / n), kNoiseStd, 0.01);
  EXPECT_NEAR(std::sqrt(g2 / n), kNoiseGradientRms, 0.02);
}

TEST(ProceduralNoise, GradientIsTheDerivative) {
  for (const double x : {0.1, 3.7, -12.25}) {
    const double y = 0.6 * x + 0.3, h = 1e-3;
    const NoiseSample v = value_noise(x, y, 11);
    const double dx = (value_noise(x + h, y, 11).value - value_noise(x - h, y, 11).value) / (2 * h);
    const double dy = (value_noise(x, y + h, 11).value - value_noise(x, y - h, 11).value) / (2 * h);
    EXPECT_NEAR(v.gradient.x(), dx, 5e-3);
    EXPECT_NEAR(v.gradient.y(), dy, 5e-3);
  }
}

void expect_cell_mean_kept(const GroundDetail& d);

TEST(GroundDetail, LeanRoughnessIsHypotOfTheFilteredSlopesAngle) {
  // lean_roughness's own arctangent against libm's, over variances from
  // none to rms slopes of 1000 (every branch of its range reduction), and
  // the cap.
  double worst = 0.0;
  for (int i = 0; i <= 4000; ++i) {
    const float variance = i == 0 ? 0.0f : std::pow(10.0f, -8.0f + 14.0f * i / 4000.0f);
    for (const float r : {0.0f, 0.2f, 0.9f}) {
      const double want = std::min(
          std::hypot(static_cast<double>(r), std::atan(std::sqrt(static_cast<double>(variance)))),
          static_cast<double>(kMaxRoughness));
      worst = std::max(worst, std::abs(lean_roughness(r, variance) - want));
    }
  }
  EXPECT_LT(worst, 4e-7);
  EXPECT_EQ(lean_roughness(1.2f, 1e6f), kMaxRoughness);
}

TEST(GroundDetail, CellScaleMeanSlopeIsKept) {
  // The relief's slope averaged over a DEM cell (10 m) is ~0: the mean
  // surface stays the DEM's. Point samples over 40 cells far from the origin.
  for (const char* name :
       {"rock", "dark_rock", "scree", "meadow", "dwarf_pine", "forest", "mud", "grass", "snow"}) {
    SCOPED_TRACE(name);
    expect_cell_mean_kept(material_preset(name)->detail);
  }
}

void expect_cell_mean_kept(const GroundDetail& d) {
  double worst = 0.0, sum2 = 0.0;
  for (int cell = 0; cell < 40; ++cell) {
    const double x0 = 746000.0 + 37.0 * cell, y0 = 4030000.0 + 11.0 * cell;
    Eigen::Vector2d mean(0, 0);
    const int k = 48;
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j)
        mean += detail_slope(d, x0 + (i + 0.5) * 10.0 / k, y0 + (j + 0.5) * 10.0 / k, 0.0)
                    .slope.cast<double>();
    worst = std::max(worst, (mean / (k * k)).norm());
    sum2 += (mean / (k * k)).squaredNorm();
  }
  // Against the relief's rms slope (0.6, 31 degrees): the cells' mean slopes
  // are a twentieth of it in rms (1.7 degrees) and an eighth at worst.
  const double rms = std::sqrt(sum2 / 40);
  EXPECT_LT(rms, 0.05 * d.bump) << "rms cell-mean slope " << rms;
  EXPECT_LT(worst, 0.125 * d.bump) << "largest cell-mean slope " << worst;
}

TEST(GroundDetail, FootprintFiltersToTheMeanAndKeepsTheVariance) {
  const GroundDetail d = rock_detail();
  // Up close every octave is there and nothing is lost.
  const DetailSlope near = detail_slope(d, 746100.3, 4030200.7, 0.0);
  EXPECT_EQ(near.lost_variance, 0.0f);
  EXPECT_GT(near.slope.norm(), 0.0f);
  // A footprint of a cell (10 m > the 6 m largest octave): the slope is the
  // mean's (0) and its whole variance, bump^2, becomes roughness.
  const DetailSlope far = detail_slope(d, 746100.3, 4030200.7, 10.0);
  EXPECT_EQ(far.slope.norm(), 0.0f);
  EXPECT_NEAR(far.lost_variance, d.bump * d.bump, 1e-4 * d.bump * d.bump);
  // The point-sampled slopes' variance is the bump's.
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0.0, 5000.0);
  double g2 = 0;
  for (int i = 0; i < 100000; ++i) g2 += detail_slope(d, u(rng), u(rng), 0.0).slope.squaredNorm();
  EXPECT_NEAR(std::sqrt(g2 / 100000), d.bump, 0.05 * d.bump);
}

// Issue 32: the relief is detail below the DEM's cell. On a 10 m mountain DEM
// the presets' relief (scale 2-4.5 m) is what it was; on a 1 cm grid of a
// footprint mud's 2 m relief would put tilted blotches 6-25 cm across on flat
// ground at a low sun, so it shrinks to the cell: at a 5 mm footprint the
// shading normal barely moves.
TEST(GroundDetail, ReliefStaysBelowTheDemsCell) {
  const Material mud = *material_preset("mud"), rock = *material_preset("rock");
  EXPECT_EQ(relief_scale(rock.detail, 10.0), rock.detail.scale);
  EXPECT_EQ(relief_scale(rock.detail, 0.0), rock.detail.scale);
  EXPECT_FLOAT_EQ(relief_scale(mud.detail, 0.01), 0.01f);
  const Eigen::Vector3f up(0, 0, 1);
  for (double x = 0.0; x < 2.0; x += 0.37) {
    const DetailedGround a = ground_detail(rock, x, 0.3 * x, 2000.0, up, 0.05);
    const DetailedGround b = ground_detail(rock, x, 0.3 * x, 2000.0, up, 0.05, 10.0);
    EXPECT_EQ(a.normal, b.normal);
    EXPECT_EQ(a.albedo, b.albedo);
  }
  double tilt_mountain = 0.0, tilt_print = 0.0;
  int n = 0;
  for (double x = 0.0; x < 0.4; x += 0.005)
    for (double y = 0.0; y < 0.4; y += 0.005, ++n) {
      const auto t = [&](double cell) {
        const Eigen::Vector3f m = ground_detail(mud, x, y, 0.0, up, 0.005, cell).normal;
        return static_cast<double>(m.head<2>().squaredNorm());
      };
      tilt_mountain += t(0.0), tilt_print += t(0.01);
    }
  const double rms_mountain = std::sqrt(tilt_mountain / n), rms_print = std::sqrt(tilt_print / n);
  EXPECT_GT(rms_mountain, 0.08) << "mud's own relief tilts the normal";
  EXPECT_LT(rms_print, 0.3 * rms_mountain) << "at 1 cm cells it is sub-footprint grain";
}

TEST(GroundDetail, AlbedoFactorKeepsTheMean) {
  const GroundDetail d = rock_detail();
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(0.0, 20000.0);
  double s = 0, s2 = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double f = albedo_factor(d, u(rng), u(rng), 0.0);
    s += f, s2 += f * f;
  }
  EXPECT_NEAR(s / n, 1.0, 0.01);
  EXPECT_NEAR(std::sqrt(s2 / n - (s / n) * (s / n)), d.variation, 0.15 * d.variation);
}

// A pixel seen from afar: a footprint F wide on flat ground of dark rock lit
// by a sun 30 degrees up. Its true value is the mean over the footprint of
// point-sampled shading (albedo x cos); 4 samples with the footprint filter
// must be far closer to it than 4 point samples (which alias: shimmer).
TEST(GroundDetail, FarDetailDoesNotAlias) {
  const Material rock = *material_preset("dark_rock");
  const Eigen::Vector3f sun = Eigen::Vector3f(0.8f, 0.2f, 0.5f).normalized();
  const Eigen::Vector3f up(0, 0, 1);
  const Eigen::Vector3f eye = Eigen::Vector3f(-0.9f, 0.1f, 0.35f).normalized();
  // Radiance under a unit sun through the ground's BSDF: bumped normal and
  // the material's roughness point-sampled, the flat normal and the
  // filtered-away relief as roughness with the footprint.
  auto shade = [&](double x, double y, double footprint) {
    const DetailedGround g = ground_detail(rock, x, y, 0.0, up, footprint);
    Material m = rock;
    m.albedo = g.albedo;
    m.roughness = g.roughness;
    const GroundBsdf bsdf(g.normal, eye, m);
    return luminance(bsdf.eval(sun)) * std::max(0.0f, g.normal.dot(sun));
  };
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double footprint = 3.0;  // metres: a pixel a few km away
  double err_filtered = 0, err_point = 0, mean_reference = 0;
  const int pixels = 120;
  for (int p = 0; p < pixels; ++p) {
    const double x0 = 746000.0 + 3.0 * p, y0 = 4030000.0;
    double reference = 0, filtered = 0, point = 0;
    for (int i = 0; i < 1024; ++i)
      reference += shade(x0 + footprint * u(rng), y0 + footprint * u(rng), 0.0) / 1024;
    for (int i = 0; i < 4; ++i) {
      const double x = x0 + footprint * u(rng), y = y0 + footprint * u(rng);
      filtered += shade(x, y, footprint) / 4;
      point += shade(x, y, 0.0) / 4;
    }
    err_filtered += (filtered - reference) * (filtered - reference);
    err_point += (point - reference) * (point - reference);
    mean_reference += reference / pixels;
  }
  const double rms_filtered = std::sqrt(err_filtered / pixels) / mean_reference;
  const double rms_point = std::sqrt(err_point / pixels) / mean_reference;
  // Relative rms error against the 1024-sample mean: the filter removes the
  // sub-pixel relief's noise (what remains is the albedo's and the relief's
  // octaves above the footprint, which the 4 samples resolve).
  EXPECT_LT(rms_filtered, 0.5 * rms_point) << rms_filtered << " vs " << rms_point;
  std::printf("far detail, relative rms error against 1024 samples: filtered %.4f, point %.4f\n",
              rms_filtered, rms_point);
}

TEST(LandForm, TopographicPositionOfPlaneAndValley) {
  terrain::HeightField plane(41, 41, 0.0f, terrain::local_georeference(10.0));
  terrain::HeightField valley = plane;
  for (int r = 0; r < 41; ++r)
    for (int c = 0; c < 41; ++c) {
      plane(c, r) = 3.0f * c - 2.0f * r;
      valley(c, r) = 5.0f * std::abs(c - 20);
    }
  const terrain::HeightField tp = topographic_position(plane, 50.0);
  EXPECT_NEAR(tp(20, 20), 0.0f, 1e-3f);  // a plane has no ridges or gullies
  const terrain::HeightField tv = topographic_position(valley, 50.0);
  // The valley floor lies below its surroundings: mean of 5|dc| over dc in
  // [-5, 5] is 5 x 30 / 11.
  EXPECT_NEAR(tv(20, 20), -5.0f * 30.0f / 11.0f, 1e-3f);
  EXPECT_GT(tv(8, 20), 0.0f - 1e-3f);
  EXPECT_THROW(topographic_position(plane, 0.0), Error);
}

// f(x, y) at n points drawn uniformly over 20 km x 20 km with seed `seed`.
template <class F>
void at_random_points(std::uint64_t seed, int n, F f) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 20000.0);
  for (int i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng);
    f(x, y);
  }
}

TEST(LandForm, RaggednessIsSmoothBoundedNoise) {
  double s = 0, s2 = 0, worst = 0;
  const int n = 20000;
  at_random_points(3, n, [&](double x, double y) {
    const double r = raggedness(x, y);
    s += r, s2 += r * r, worst = std::max(worst, std::abs(r));
  });
  EXPECT_NEAR(s / n, 0.0, 0.05);
  EXPECT_NEAR(std::sqrt(s2 / n), 0.5, 0.1);
  EXPECT_LT(worst, 2.0);
  EXPECT_EQ(raggedness(1.0, 2.0), raggedness(1.0, 2.0));
}

TEST(LandForm, RaggednessSeenByAFootprintKeepsTheOctavesItResolves) {
  // A 100 m footprint keeps the 800, 400 and 200 m octaves (of 800 down to
  // 25 m) and drops the rest: what is left is the noise's coarse part, a
  // little weaker, centred on the same mean and close to the point value;
  // a footprint wider than the largest octave sees the mean, 0.
  double s = 0, s2 = 0, d2 = 0;
  const int n = 20000;
  at_random_points(5, n, [&](double x, double y) {
    const double r = raggedness(x, y, 100.0), point = raggedness(x, y);
    s += r, s2 += r * r, d2 += (r - point) * (r - point);
    EXPECT_EQ(raggedness(x, y, 2000.0), 0.0f);
  });
  EXPECT_NEAR(s / n, 0.0, 0.05);
  EXPECT_GT(std::sqrt(s2 / n), 0.35);
  EXPECT_LT(std::sqrt(s2 / n), 0.5);
  EXPECT_GT(std::sqrt(d2 / n), 0.05);  // the fine octaves are gone
  EXPECT_LT(std::sqrt(d2 / n), 0.25);
  EXPECT_EQ(raggedness(7.0, 9.0, 0.0), raggedness(7.0, 9.0));
}

TEST(LandForm, ClumpsCoverTheirShareAsSeparateBushesAndFadeToItFarAway) {
  // Scrub in clumps of 20 m over 35 % of the ground: close up the mask is
  // mostly all or nothing (bushes and gaps, not a tint) and covers 35 %; at
  // any footprint its mean over the ground stays 35 % (no shift of colour
  // with distance), and past two clump sizes a footprint sees the mean alone.
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0.0, 50000.0);
  const int n = 40000;
  for (const double footprint : {0.0, 8.0, 15.0, 30.0}) {
    double sum = 0;
    int between = 0;
    for (int i = 0; i < n; ++i) {
      const float m = clump_mask(u(rng), u(rng), 20.0f, 0.35f, 5, footprint);
      sum += m;
      between += m > 0.05f && m < 0.95f;
    }
    std::printf("clumps at footprint %.0f m: mean %.3f, %.1f %% neither bush nor gap\n", footprint,
                sum / n, 100.0 * between / n);
    EXPECT_NEAR(sum / n, 0.35, 0.03) << "footprint " << footprint;
    if (footprint == 0.0) {
      EXPECT_LT(static_cast<double>(between) / n, 0.2);
    }
  }
  EXPECT_EQ(clump_mask(123.0, 456.0, 20.0f, 0.35f, 5, 45.0), 0.35f);
  // Another seed, other bushes.
  int differ = 0;
  for (int i = 0; i < 1000; ++i) {
    const double x = u(rng), y = u(rng);
    differ += (clump_mask(x, y, 20.0f, 0.35f, 5, 0.0) > 0.5f) !=
              (clump_mask(x, y, 20.0f, 0.35f, 6, 0.0) > 0.5f);
  }
  EXPECT_GT(differ, 200);
}

}  // namespace
}  // namespace drift::render

namespace drift::render {
namespace {

// Correlation of the albedo factor between points `gap` metres apart along
// `step` on a plane face of normal n through the origin (the same footprint
// everywhere: point samples).
double albedo_correlation(const Material& m, const Eigen::Vector3f& n, const Eigen::Vector3f& step,
                          double gap) {
  const Eigen::Vector3f across = n.cross(step).normalized();
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(-2e3, 2e3);
  double sa = 0, sb = 0, sab = 0, saa = 0, sbb = 0;
  const int count = 20000;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d p = (step.cast<double>() * u(rng) + across.cast<double>() * u(rng));
    const Eigen::Vector3d q = p + step.cast<double>() * gap;
    const double a = ground_detail(m, p.x(), p.y(), p.z(), n, 0.0).albedo.y();
    const double b = ground_detail(m, q.x(), q.y(), q.z(), n, 0.0).albedo.y();
    sa += a, sb += b, sab += a * b, saa += a * a, sbb += b * b;
  }
  const double ma = sa / count, mb = sb / count;
  return (sab / count - ma * mb) / std::sqrt((saa / count - ma * ma) * (sbb / count - mb * mb));
}

TEST(GroundDetail, SteepFacesAreNotStreakedDownTheirFallLine) {
  // A 70-degree face: read from the map's plane alone, its detail would be
  // stretched 1 / cos(70) = 2.9 times down the fall line (streaks), so points
  // 20 m apart down it would correlate far more than points 20 m apart across
  // it (0.79 against 0.59 measured; 0.60 against 0.59 triplanar). Triplanar, the two agree.
  // The joints are left out: their rows run across the face on purpose
  // (ledges, JointsStandInRowsOnCliffs below).
  Material rock = *material_preset("dark_rock");
  rock.detail.fracture = 0.0f;
  const float slope = 70.0f * std::numbers::pi_v<float> / 180.0f;
  for (const float azimuth : {0.0f, 0.6f}) {  // facing east, and turned
    const Eigen::Vector3f n(std::sin(slope) * std::cos(azimuth),
                            std::sin(slope) * std::sin(azimuth), std::cos(slope));
    const Eigen::Vector3f horizontal = Eigen::Vector3f(0, 0, 1).cross(n).normalized();
    const Eigen::Vector3f fall = n.cross(horizontal).normalized();  // in the face, down-dip
    const double along = albedo_correlation(rock, n, fall, 20.0);
    const double across = albedo_correlation(rock, n, horizontal, 20.0);
    std::printf(
        "70-degree face, azimuth %.1f: correlation at 20 m down the fall line %.3f, "
        "across %.3f\n",
        azimuth, along, across);
    EXPECT_NEAR(along, across, 0.06) << "azimuth " << azimuth;
  }
  // Gentle ground keeps reading the map's plane: the same albedo as before.
  const Eigen::Vector3f gentle = Eigen::Vector3f(0.3f, 0.1f, 1.0f).normalized();
  EXPECT_EQ(ground_detail(rock, 123.4, 567.8, 2000.0, gentle, 0.5).albedo,
            ground_detail(rock, 123.4, 567.8, -50.0, gentle, 0.5).albedo);
}

}  // namespace
}  // namespace drift::render

namespace drift::render {
namespace {

TEST(GroundDetail, JointedRockKeepsItsMeanAndStandsInRowsOnCliffs) {
  // Rock's blocks (fracture 1: all of the relief in blocks): the dark joints
  // keep the albedo's mean (factor 1 on average, < 0.7 in the joints, exactly
  // 1 once the footprint covers blocks), and on a cliff (layered) the relief
  // tilts mostly across the rows (ledges: 3x the variance), on the map's
  // plane alike both ways.
  GroundDetail d = material_preset("dark_rock")->detail;
  d.fracture = 1.0f;
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-5e3, 5e3);
  for (const bool layered : {false, true}) {
    double sum = 0, darkest = 1, gx2 = 0, gy2 = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
      const DetailSlope s = detail_slope(d, u(rng), u(rng), 0.0, layered);
      sum += s.joint_factor, darkest = std::min<double>(darkest, s.joint_factor);
      gx2 += s.slope.x() * s.slope.x(), gy2 += s.slope.y() * s.slope.y();
    }
    SCOPED_TRACE(layered ? "cliff" : "map plane");
    EXPECT_NEAR(sum / n, 1.0, 0.01);
    EXPECT_LT(darkest, 0.7);
    EXPECT_NEAR(std::sqrt((gx2 + gy2) / n), d.bump, 0.05 * d.bump);
    if (layered) {
      EXPECT_GT(gy2 / gx2, 2.5);
    } else {
      EXPECT_NEAR(gy2 / gx2, 1.0, 0.15);
    }
    EXPECT_EQ(detail_slope(d, 12.3, 45.6, 20.0, layered).joint_factor, 1.0f);
  }
}

}  // namespace
}  // namespace drift::render
