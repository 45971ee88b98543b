// Mud's heave (docs/marks.md, "Mud's heave"; terrain/marks/displacement.cpp):
// soft mud fails undrained over about a footing width beyond each edge
// (Prandtl's mechanism, Terzaghi 1943), so the displaced volume stands in a
// band whose width grows with the footing, not in a rim on the contact's
// ring; volume is kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "terrain/marks/marks.h"
#include "tests/marks/shapes.h"

namespace drift::marks {
namespace {

constexpr double kCell = 0.005;  // 5 mm cells
constexpr int kSize = 160;       // 80 cm
constexpr double kDepth = 0.01;  // pressed 1 cm

struct Print {
  terrain::Grid<double> h;
  double compressed = 0.0;
};

// A square plate of half side `half` pressed kDepth into mud of `heave`,
// held a step, lifted and left four steps to slump; worked at `level`
// (paper 000, 3.6: 1 full resolution, 2 half).
Print press(double half, double heave, int level = 1) {
  MaterialField mud = testing::only("mud");
  mud.table[0].heave = heave;
  MarksSimulation sim(testing::flat(kSize, kCell, 1.0f), mud, {});
  const ObjectShape shape = ObjectShape::of(testing::box(half, half, 0.02));
  MarkObject object;
  object.motion = Motion::Place;
  object.resolution = level;
  const double c = kSize / 2.0;
  Print out;
  Pose at{testing::at_cell(sim, c, c, 1.0 + 0.02 - kDepth), Eigen::Quaterniond::Identity()};
  out.compressed += sim.move(shape, object, at, at, true).compressed;
  sim.end_step();
  const Pose up{testing::at_cell(sim, c, c, 1.5), Eigen::Quaterniond::Identity()};
  out.compressed += sim.move(shape, object, at, up, false).compressed;
  sim.end_step();
  for (int s = 0; s < 4; ++s) {
    sim.move(shape, object, up, up, false);
    sim.end_step();
  }
  out.h = sim.heights();
  return out;
}

// The distance beyond the plate's edge (m, along the nearest side) within
// which 90 % of the raised volume stands: the heave's width.
double heave_width(const terrain::Grid<double>& h, double half) {
  std::vector<std::pair<double, double>> raised;  // (distance, height)
  double total = 0.0;
  const double c = kSize / 2.0;
  for (int r = 0; r < kSize; ++r)
    for (int col = 0; col < kSize; ++col) {
      const double up = h(col, r) - 1.0;
      if (!(up > 0.0)) continue;
      const double d = std::max(std::abs(col - c), std::abs(r - c)) * kCell - half;
      raised.emplace_back(d, up);
      total += up;
    }
  std::sort(raised.begin(), raised.end());
  double sum = 0.0;
  for (const auto& [d, up] : raised)
    if ((sum += up) >= 0.9 * total) return d;
  return 0.0;
}

double volume_change(const Print& p) {
  return testing::volume(p.h, kCell) - kSize * kSize * kCell * kCell + p.compressed;
}

TEST(MarksHeave, MudHeaveWidthGrowsWithTheFootingAndKeepsTheVolume) {
  const double small_half = 0.03, large_half = 0.06;  // 6 and 12 cm plates
  const Print small = press(small_half, 1.0), large = press(large_half, 1.0);
  const double ws = heave_width(small.h, small_half), wl = heave_width(large.h, large_half);
  // The band is about a footing width (the plate's side) wide: twice as wide
  // for a plate twice as large.
  EXPECT_NEAR(wl / ws, 2.0, 0.5) << "heave widths " << ws << " and " << wl << " m";
  RecordProperty("heave_widths_mm", std::to_string(ws * 1e3) + " " + std::to_string(wl * 1e3));
  EXPECT_GT(ws, 0.5 * 2 * small_half) << "small plate's heave";
  EXPECT_LT(wl, 1.5 * 2 * large_half) << "large plate's heave";
  // Volume: what the ground holds is what it held less what was compressed.
  EXPECT_NEAR(volume_change(small), 0.0, 1e-9);
  EXPECT_NEAR(volume_change(large), 0.0, 1e-9);
}

// The paper's rule (heave 0) keeps the volume on the contact's ring: a rim a
// few cells wide whatever the footing, standing higher than the heave.
TEST(MarksHeave, WithoutHeaveTheRimStaysOnTheRing) {
  const Print ring = press(0.06, 0.0), heave = press(0.06, 1.0);
  const double w = heave_width(ring.h, 0.06);
  EXPECT_LT(w, 0.25 * 0.12) << "rim width (m) on a 12 cm plate";
  EXPECT_NEAR(volume_change(ring), 0.0, 1e-9);
  double top0 = 0.0, top1 = 0.0;
  for (double v : ring.h.values()) top0 = std::max(top0, v - 1.0);
  for (double v : heave.h.values()) top1 = std::max(top1, v - 1.0);
  EXPECT_LT(top1, 0.5 * top0) << "heave top " << top1 << " m against the ring's " << top0;
}

// Multi-resolution (3.6): the coarse window is widened for the heave's band
// as the full-resolution one is, so the heave at half resolution is as wide
// as at full and not cut (heaped) at the window's edge; volume kept.
TEST(MarksHeave, HalfResolutionKeepsTheHeavesWidth) {
  const double half = 0.06;
  const Print fine = press(half, 1.0), coarse = press(half, 1.0, 2);
  const double wf = heave_width(fine.h, half), wc = heave_width(coarse.h, half);
  RecordProperty("heave_widths_mm", std::to_string(wf * 1e3) + " " + std::to_string(wc * 1e3));
  EXPECT_NEAR(wc / wf, 1.0, 0.2) << "heave widths " << wf << " m (full), " << wc << " m (half)";
  EXPECT_NEAR(volume_change(coarse), 0.0, 1e-9);
}

}  // namespace
}  // namespace drift::marks
