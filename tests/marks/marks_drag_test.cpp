// Dragging (paper 000, 3.3-3.4, fig. 10, table 1): a ball dragged 10 cells a
// step, swept, against the same drag cut into 10 sub-steps of one cell.
#include <gtest/gtest.h>

#include <cmath>

#include "terrain/marks/marks.h"
#include "tests/marks/shapes.h"

namespace drift::marks {
namespace {

// The shapes and grounds of tests/marks/shapes.h.
using namespace testing;

constexpr double kCell = 0.01, kRadius = 0.06, kDepth = 0.02;
constexpr int kWidth = 160, kHeight = 48, kRow = 24, kStart = 20, kSteps = 10, kStride = 10;

terrain::Grid<double> drag(Motion motion, const char* material = "sand") {
  terrain::HeightField ground(kWidth, kHeight, 1.0f, terrain::local_georeference(kCell));
  MarksSimulation sim(ground, only(material), {});
  const ObjectShape shape = ObjectShape::of(sphere(kRadius));
  MarkObject object;
  object.motion = motion;
  const double z = 1.0 + kRadius - kDepth;
  Pose from{at_cell(sim, kStart, kRow, z), Eigen::Quaterniond::Identity()};
  sim.move(shape, object, from, from, true);
  sim.end_step();
  for (int s = 1; s <= kSteps; ++s) {
    const Pose to{at_cell(sim, kStart + s * kStride, kRow, z), Eigen::Quaterniond::Identity()};
    sim.move(shape, object, from, to, false);
    sim.end_step();
    from = to;
  }
  return sim.heights();
}

// Range of the trough's floor along the track's middle (between the start and
// the end, away from both): a streaked track has ridges between its dents.
double streak(const terrain::Grid<double>& h) {
  double lo = 1e9, hi = -1e9;
  for (int c = kStart + 10; c <= kStart + kSteps * kStride - 10; ++c)
    lo = std::min(lo, h(c, kRow)), hi = std::max(hi, h(c, kRow));
  return hi - lo;
}

TEST(MarksDrag, SweptDragMatchesTenSubStepsWithoutStreaks) {
  const auto swept = drag(Motion::Sweep), stepped = drag(Motion::SubSteps);
  // Metric: root mean square height difference over the track's cells (rows
  // within the ball's radius, start to end), relative to the mark's depth.
  double sum = 0;
  int n = 0;
  for (int r = kRow - 6; r <= kRow + 6; ++r)
    for (int c = kStart; c <= kStart + kSteps * kStride; ++c, ++n)
      sum += std::pow(swept(c, r) - stepped(c, r), 2);
  const double rms = std::sqrt(sum / n) / kDepth;
  EXPECT_LE(rms, 0.15) << "rms difference / depth";
  EXPECT_LE(streak(swept), 0.02 * kDepth) << "swept trough floor range (m)";
  EXPECT_LE(streak(stepped), 0.02 * kDepth) << "sub-stepped trough floor range (m)";
}

TEST(MarksDrag, PlacingWithoutSweepLeavesStreaks) {
  // The metric above sees the paper's fig. 10 (left): dents with ridges between.
  EXPECT_GT(streak(drag(Motion::Place)), 0.5 * kDepth);
}

TEST(MarksDrag, NothingIsSentBackwards) {
  const auto h = drag(Motion::Sweep);
  for (int r = 0; r < kHeight; ++r)
    for (int c = 0; c < kStart - 6 - 2; ++c) EXPECT_LE(h(c, r), 1.0 + 1e-12) << c << "," << r;
  // Nothing falls back into the trough behind the ball: its floor stays at the
  // ball's bottom (the pressed start, where the rim slumps in, aside).
  for (int c = kStart + 8; c <= kStart + kSteps * kStride - 8; ++c)
    EXPECT_LE(h(c, kRow), 1.0 - 0.99 * kDepth) << "trough floor, column " << c;
  // The material goes ahead: a mound in front of the ball's last position.
  double front = 0;
  for (int c = kStart + kSteps * kStride; c < kWidth; ++c)
    front = std::max(front, h(c, kRow) - 1.0);
  EXPECT_GT(front, 0.5 * kDepth);
}

}  // namespace
}  // namespace drift::marks
