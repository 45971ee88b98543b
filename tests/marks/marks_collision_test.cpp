// Collision (paper 000, 3.3): the object's bottom from below by the CPU
// z-buffer and by OSMesa, the sweep of a moving object, keyframes, the run's
// determinism and the multi-resolution path.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "terrain/error.h"
#include "terrain/marks/marks.h"
#include "terrain/marks/multires.h"
#include "tests/marks/shapes.h"

namespace drift::marks {
namespace {

using testing::flat;
using testing::only;
using testing::sphere;
const Eigen::Quaterniond kId = Eigen::Quaterniond::Identity();

TEST(MarksCollision, OsmesaAndCpuBottomsAgreeToFloatDepthOnAHighDem) {
  // A 12 cm ball over 1 cm cells at 3000 m: float depth measured from the
  // object's lowest point keeps the print's centimetres exact.
  GridFrame frame{0.005, -0.005, 0.01, 0.01};
  const ObjectShape shape = ObjectShape::of(sphere(0.06));
  const Pose pose{frame.to_world(20.3, 19.6, 3000.0), Eigen::Quaterniond::Identity()};
  const CellTriangles tris = posed_triangles(shape, pose, frame);
  BottomMap cpu, gl;
  cpu.window = gl.window = footprint_window(tris, 2, 64, 64);
  make_bottom_rasteriser(BottomRenderer::Cpu)->render(tris, cpu);
  make_bottom_rasteriser(BottomRenderer::OpenGL)->render(tris, gl);
  int both = 0, differ = 0;
  double worst = 0;
  for (std::size_t i = 0; i < cpu.z.size(); ++i) {
    if (std::isfinite(cpu.z[i]) != std::isfinite(gl.z[i])) ++differ;
    if (!std::isfinite(cpu.z[i]) || !std::isfinite(gl.z[i])) continue;
    ++both;
    worst = std::max(worst, std::abs(cpu.z[i] - gl.z[i]));
  }
  EXPECT_GT(both, 100);
  EXPECT_LE(differ, 2) << "cells covered by one renderer only (edge rules)";
  EXPECT_LE(worst, 1e-5) << "largest difference of bottoms (m)";
  // The lowest point is the ball's bottom (tessellation: within 0.5 mm).
  double lowest = 1e9;
  for (double z : cpu.z) lowest = std::min(lowest, z);
  EXPECT_NEAR(lowest, 3000.0 - 0.06, 5e-4);
}

TEST(MarksCollision, SweptBallIsTheCapsuleBetweenItsPositions) {
  GridFrame frame{0.5, -0.5, 1.0, 1.0};
  const ObjectShape shape = ObjectShape::of(sphere(6.0));
  const Eigen::Vector3d from = frame.to_world(10, 20, 10.0);
  const Pose to{frame.to_world(30, 20, 10.0), Eigen::Quaterniond::Identity()};
  const CellTriangles swept = swept_triangles(shape, from, to, frame);
  BottomMap b, at_from, at_to;
  b.window = at_from.window = at_to.window = {0, 0, 48, 40};
  auto cpu = make_bottom_rasteriser(BottomRenderer::Cpu);
  cpu->render(swept, b);
  cpu->render(posed_triangles(shape, {from, to.rotation}, frame), at_from);
  cpu->render(posed_triangles(shape, to, frame), at_to);
  for (int c = 10; c <= 30; ++c) EXPECT_NEAR(b.at(c, 20), 4.0, 0.1) << "centre line, column " << c;
  for (std::size_t i = 0; i < b.z.size(); ++i)
    EXPECT_LE(b.z[i], std::min(at_from.z[i], at_to.z[i]) + 1e-9) << "the sweep holds both ends";
  // Between the ends, off the centre line, the capsule's profile.
  EXPECT_NEAR(b.at(20, 24), 10.0 - std::sqrt(36.0 - 16.0), 0.15);
}

TEST(MarksTrajectory, LinearPositionSlerpRotation) {
  Trajectory t;
  t.keys = {{0.0, {0, 0, 0}, rotation_from_ypr(0, 0, 0)},
            {2.0, {4, 2, -2}, rotation_from_ypr(90, 0, 0)}};
  t.validate("test");
  const Pose p = t.at(0.5);
  EXPECT_NEAR((p.position - Eigen::Vector3d(1, 0.5, -0.5)).norm(), 0.0, 1e-12);
  const Eigen::Vector3d x = p.rotation * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::atan2(x.y(), x.x()) * 180 / std::numbers::pi, 22.5, 1e-9);
  // pitch raises the object's +x end
  EXPECT_GT((rotation_from_ypr(0, 10, 0) * Eigen::Vector3d::UnitX()).z(), 0.0);
}

TEST(MarksTrajectory, BadKeyframesAreRefused) {
  Trajectory t;
  t.keys = {{1.0, {0, 0, 0}, kId}, {0.5, {1, 0, 0}, kId}};
  EXPECT_THROW(t.validate("walk.toml: object 1"), Error);
  t.keys = {{0.0, {0, NAN, 0}, kId}};
  EXPECT_THROW(t.validate("walk.toml: object 1"), Error);
  t.keys.clear();
  EXPECT_THROW(t.validate("walk.toml: object 1"), Error);
}

MarksResult run_two_objects() {
  const terrain::HeightField ground = flat(96, 0.01, 1.0f);
  const GridFrame f = GridFrame::of(ground.geo());
  MarkObject press, dragged;
  press.mesh = dragged.mesh = sphere(0.05);
  press.trajectory.keys = {{0.0, f.to_world(20, 20, 1.08), kId},
                           {0.3, f.to_world(20, 20, 1.035), kId}};
  dragged.trajectory.keys = {{0.0, f.to_world(10, 60, 1.035), kId},
                             {0.5, f.to_world(80, 60, 1.035), kId}};
  dragged.material = material_preset("mud");
  MarksOptions o;
  o.step = 0.05;
  return simulate_marks(ground, {press, dragged}, only("sand"), o);
}

TEST(MarksDeterminism, SameBitsWhateverTheThreadCount) {
  MarksResult one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = run_two_objects();
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = run_two_objects();
  }
  ASSERT_EQ(one.heights.values(), two.heights.values());
  ASSERT_EQ(one.disturbed.values(), two.disturbed.values());
  EXPECT_GT(one.report.collided, 0.0);
}

TEST(MarksMultiResolution, HalfResolutionKeepsVolumeAndTheMarksDepth) {
  for (int level : {2, 4}) {
    MarksSimulation sim(flat(96, 0.01, 1.0f), only("sand"), {});
    const ObjectShape shape = ObjectShape::of(sphere(0.08));
    MarkObject o;
    o.resolution = level;
    const Pose p{sim.frame().to_world(48, 48, 1.06), kId};
    const double before = testing::volume(sim.heights(), 0.01);
    const StepReport r = sim.move(shape, o, p, p, true);
    sim.end_step();
    EXPECT_GT(r.collided, 0.0);
    EXPECT_NEAR(testing::volume(sim.heights(), 0.01), before, 1e-12 * before) << "level " << level;
    EXPECT_NEAR(sim.heights()(48, 48), 1.0 - 0.02, 0.25 * 0.02) << "level " << level;
  }
}

TEST(MarksMultiResolution, TheCameraChoosesTheLevelByProjectedCellSize) {
  MarksOptions o;
  o.camera = MarksCamera{{0, 0, 1.7}, 40.0, 1280};
  MarksSimulation sim(flat(8, 0.01, 0.0f), only("sand"), o);
  MarkObject auto_level;
  auto_level.resolution = 0;
  // focal 1758 px: a 1 cm cell is a pixel at 17.6 m, half a pixel at 35 m.
  EXPECT_EQ(sim.resolution_for(auto_level, {10, 0, 0}), 1);
  EXPECT_EQ(sim.resolution_for(auto_level, {50, 0, 0}), 2);
  EXPECT_EQ(sim.resolution_for(auto_level, {100, 0, 0}), 4);
}

}  // namespace
}  // namespace drift::marks
