// Physics of marks (paper 000): volume bookkeeping of compression and
// displacement, the object's bottom as a ceiling, erosion to the material's
// angle, symmetry and per-region materials.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "terrain/error.h"
#include "terrain/marks/marks.h"
#include "tests/marks/shapes.h"

namespace drift::marks {
namespace {

// The shapes and grounds of tests/marks/shapes.h.
using namespace testing;

constexpr double kCell = 0.01;    // 1 cm cells
constexpr double kRadius = 0.06;  // a 12 cm ball
constexpr double kDepth = 0.02;   // pressed 2 cm into the ground

struct Press {
  MarksSimulation sim;
  ObjectShape shape = ObjectShape::of(sphere(kRadius));
  MarkObject object;
  Pose pose;
  StepReport report;

  Press(const MaterialField& m, double col = 32, double row = 32, int n = 64)
      : sim(flat(n, kCell, 1.0f), m, MarksOptions{}) {
    object.mesh = shape.mesh;
    pose.position = at_cell(sim, col, row, 1.0 + kRadius - kDepth);
    report = sim.move(shape, object, pose, pose, true);
    sim.end_step();
  }
  BottomMap bottom() const {
    BottomMap b;
    const CellTriangles t = posed_triangles(shape, pose, sim.frame());
    b.window = footprint_window(t, 0, sim.heights().width(), sim.heights().height());
    make_bottom_rasteriser(BottomRenderer::Cpu)->render(t, b);
    return b;
  }
};

MaterialField custom(double alpha) {
  MaterialField f;
  f.table = {Material{"custom", 30.0, alpha, 0.2}};
  return f;
}

TEST(MarksVolume, CollidedVolumeIsTheSphericalCap) {
  Press p(only("sand"));
  const double cap = std::numbers::pi * kDepth * kDepth * (3 * kRadius - kDepth) / 3;
  EXPECT_NEAR(p.report.collided, cap, 0.03 * cap) << "cap " << cap;
}

TEST(MarksVolume, AlphaOneKeepsVolumeAlphaZeroRemovesTheCollidedVolume) {
  const double before = 64 * 64 * 1.0 * kCell * kCell;
  for (double alpha : {1.0, 0.0, 0.3, 0.8}) {
    Press p(custom(alpha));
    const double after = volume(p.sim.heights(), kCell);
    const double expected = -(1.0 - alpha) * p.report.collided;
    // Double precision bookkeeping: only rounding of ~4000 heights of 1 m.
    EXPECT_NEAR(after - before, expected, 1e-12 * before + 1e-9 * p.report.collided)
        << "alpha " << alpha << ": change " << after - before << " expected " << expected;
    EXPECT_NEAR(p.report.displaced, alpha * p.report.collided, 1e-12);
  }
}

TEST(MarksCeiling, NoGroundAboveTheObjectsBottom) {
  for (const char* m : {"sand", "mud", "snow"}) {
    Press p(only(m));
    const BottomMap b = p.bottom();
    int under = 0;
    for (int r = b.window.row0; r < b.window.row0 + b.window.height; ++r)
      for (int c = b.window.col0; c < b.window.col0 + b.window.width; ++c) {
        if (!std::isfinite(b.at(c, r))) continue;
        ++under;
        EXPECT_LE(p.sim.heights()(c, r), b.at(c, r) + 1e-12) << m << " cell " << c << "," << r;
      }
    EXPECT_GT(under, 100);  // pi (6 cells)^2
  }
}

// Steps with no object: the remembered cells go on relaxing.
void settle(MarksSimulation& sim, int steps) {
  for (int i = 0; i < steps; ++i) sim.end_step();
}

double max_excess(const MarksSimulation& sim, const MaterialField& m) {
  std::vector<terrain::SlopeRule> rules;
  for (const Material& x : m.table) rules.push_back(x.slope_rule());
  const terrain::SlopeCells cells{rules, m.index.empty() ? nullptr : &m.index, nullptr, nullptr};
  return terrain::max_slope_excess(sim.heights(), cells, {kCell, kCell, 0, 0});
}

TEST(MarksErosion, NoSlopeAboveThetaOnceTheObjectHasLeft) {
  for (const char* name : {"sand", "mud"}) {
    Press p(only(name));
    settle(p.sim, 10);
    const double excess = max_excess(p.sim, p.sim.materials());
    // Relaxation stops at 1e-4 of a cell of excess; allow for the last pass.
    EXPECT_LE(excess, 2e-4 * kCell) << name;
  }
}

TEST(MarksErosion, SandRimsSlumpMudWallsStandSnowHasNoRim) {
  Press sand(only("sand")), mud(only("mud")), snow(only("snow"));
  settle(sand.sim, 10), settle(mud.sim, 10), settle(snow.sim, 10);
  auto steepest = [](const MarksSimulation& s) {
    double worst = 0;
    const auto& h = s.heights();
    for (int r = 1; r < h.height() - 1; ++r)
      for (int c = 1; c < h.width() - 1; ++c)
        worst = std::max({worst, std::abs(h(c + 1, r) - h(c, r)), std::abs(h(c, r + 1) - h(c, r))});
    return std::atan(worst / kCell) * 180 / std::numbers::pi;
  };
  auto rim = [](const MarksSimulation& s) {
    double top = -1e9;
    for (double v : s.heights().values()) top = std::max(top, v);
    return top - 1.0;
  };
  EXPECT_LE(steepest(sand.sim), 30.5);
  // Walls far steeper than sand's (the ball's own flank, 48 degrees at the
  // contact's edge, read over a 1 cm cell: 39 degrees).
  EXPECT_GT(steepest(mud.sim), 35.0);
  EXPECT_LE(steepest(mud.sim), 60.5 + 0.0) << "mud wall";
  EXPECT_GT(rim(sand.sim), 0.001);
  // Mud's heave (docs/marks.md) spreads its rim about a footing wide, so it
  // stands lower than sand's; by the paper's rule (heave 0) the displaced
  // volume stays on the ring, and at theta 60 it stands higher than sand's.
  EXPECT_LT(rim(mud.sim), 0.5 * rim(sand.sim)) << "mud's heave";
  MaterialField ring = only("mud");
  ring.table[0].heave = 0.0;
  Press paper(ring);
  settle(paper.sim, 10);
  EXPECT_GT(rim(paper.sim), rim(sand.sim));  // alpha 0.8 but steeper, so higher rims
  EXPECT_LE(rim(snow.sim), 0.0);             // alpha 0: compressed, no rim
}

// Compression and displacement are symmetric (a material that does not slip:
// erosion's roughness, sigma, gives each cell its own angle and so breaks the
// symmetry on purpose, paper 000, 3.5).
TEST(MarksSymmetry, ABallPressedStraightDownLeavesASymmetricMark) {
  MaterialField stiff;
  stiff.table = {Material{"stiff", 90.0, 1.0, 0.2}};
  Press p(stiff, 32, 32, 65);
  const auto& h = p.sim.heights();
  const int n = h.width();
  double worst = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      worst = std::max(worst, std::abs(h(c, r) - h(n - 1 - c, r)));
      worst = std::max(worst, std::abs(h(c, r) - h(c, n - 1 - r)));
      worst = std::max(worst, std::abs(h(c, r) - h(r, c)));
    }
  // The mesh's float vertices are symmetric to ~1e-9 m at 6 cm.
  EXPECT_LE(worst, 1e-8) << "largest asymmetry (m)";
}

// A 96 x 48 field of 1 cm cells in materials `m` (a region each half) with a
// ball pressed kDepth into the middle of each half.
// (A pointer: the simulation is not movable.)
std::unique_ptr<MarksSimulation> press_both_halves(const MaterialField& m) {
  auto sim = std::make_unique<MarksSimulation>(
      terrain::HeightField(96, 48, 1.0f, terrain::local_georeference(kCell)), m, MarksOptions{});
  const ObjectShape shape = ObjectShape::of(sphere(kRadius));
  MarkObject object;
  for (double col : {24.0, 72.0}) {
    const Pose pose{at_cell(*sim, col, 24, 1.0 + kRadius - kDepth), Eigen::Quaterniond::Identity()};
    sim->move(shape, object, pose, pose, true);
  }
  return sim;
}

TEST(MarksMaterials, PerRegionMaterialsFromASnowDepthRaster) {
  // The west half under 30 cm of snow, the east half bare sand.
  terrain::Grid<float> snow_depth(96, 48, 0.0f);
  for (int r = 0; r < 48; ++r)
    for (int c = 0; c < 48; ++c) snow_depth(c, r) = 0.3f;
  MaterialField m = materials_from_snow_depth(snow_depth, 0.01, *material_preset("sand"),
                                              *material_preset("snow"));
  const auto pressed = press_both_halves(m);
  MarksSimulation& sim = *pressed;
  settle(sim, 5);
  double snow_top = -1, sand_top = -1;
  for (int r = 0; r < 48; ++r)
    for (int c = 0; c < 96; ++c)
      (c < 48 ? snow_top : sand_top) = std::max(c < 48 ? snow_top : sand_top, sim.heights()(c, r));
  EXPECT_LE(snow_top, 1.0) << "snow: compressed, no rim";
  EXPECT_GT(sand_top, 1.001) << "sand: displaced into a rim";
  EXPECT_LT(sim.heights()(24, 24), 1.0 - 0.9 * kDepth);
}

// Issue 32 item 4: the ground's materials from a raster a user paints (0 sand,
// 1 mud, ...): a ball pressed into each half slumps by that half's material;
// a cell that holds no material's index is refused, naming it.
TEST(MarksMaterials, PerRegionMaterialsFromAPaintedRaster) {
  terrain::Grid<float> painted(96, 48, 0.0f);
  for (int r = 0; r < 48; ++r)
    for (int c = 0; c < 48; ++c) painted(c, r) = 1.0f;  // the west half mud
  const MaterialField m = materials_from_raster(
      painted, {*material_preset("sand"), *material_preset("mud")}, "paint.tif");
  const auto pressed = press_both_halves(m);
  MarksSimulation& sim = *pressed;
  settle(sim, 10);
  auto steepest = [&](int c0, int c1) {
    double worst = 0;
    for (int r = 0; r < 47; ++r)
      for (int c = c0; c < c1; ++c)
        worst = std::max(worst, std::abs(sim.heights()(c + 1, r) - sim.heights()(c, r)));
    return std::atan(worst / kCell) * 180 / std::numbers::pi;
  };
  EXPECT_GT(steepest(4, 44), 35.0) << "mud's walls stand";
  EXPECT_LE(steepest(52, 92), 30.5) << "sand's slump to 30 degrees";
  painted(5, 7) = 0.5f;
  try {
    materials_from_raster(painted, {*material_preset("sand"), *material_preset("mud")},
                          "paint.tif");
    ADD_FAILURE() << "a fraction passed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("paint.tif: cell (5, 7) holds 0.5"), std::string::npos)
        << e.what();
  }
}

TEST(MarksMaterials, PresetsAreThePapers) {
  EXPECT_EQ(material_preset("sand")->theta_deg, 30.0);
  EXPECT_EQ(material_preset("sand")->alpha, 1.0);
  EXPECT_EQ(material_preset("mud")->theta_deg, 60.0);
  EXPECT_EQ(material_preset("mud")->alpha, 0.8);
  EXPECT_EQ(material_preset("snow")->theta_deg, 90.0);
  EXPECT_EQ(material_preset("snow")->alpha, 0.0);
  EXPECT_FALSE(material_preset("gravel"));
}

}  // namespace
}  // namespace drift::marks
