// Marks block by block (terrain/marks/marks_blocks.h, issue 36 item 3): a
// ground cut artificially into small blocks, each worked on its window, gives
// the one-pass run's heights and disturbance bit for bit, whether the halo
// was wide enough at once or had to be doubled, and blocks no object comes
// near are copied as they are.
#include "terrain/marks/marks_blocks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "terrain/marks/marks.h"
#include "terrain/raster_io.h"
#include "tests/marks/shapes.h"
#include "tests/test_files.h"

namespace drift::marks {
namespace {

constexpr double kCell = 0.01;
constexpr int kWidth = 224, kHeight = 110;

// Rolling ground (a few millimetres of relief), so objects that follow it
// stand on heights read from the whole raster.
terrain::HeightField rolling() {
  terrain::HeightField g(kWidth, kHeight, 1.0f, terrain::local_georeference(kCell));
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      g(x, y) = static_cast<float>(1.0 + 0.004 * std::sin(x / 7.0) + 0.003 * std::cos(y / 5.0));
  return g;
}

Eigen::Vector3d world(const terrain::HeightField& g, double col, double row, double z) {
  const GridFrame f = GridFrame::of(g.geo());
  return f.to_world(col, row, z);
}

// A 20 cm ball dragged 10 cells a step (swept) across several blocks,
// following the ground 2 cm deep; a box of mud pressed 2 cm and held three
// steps, then lifted, standing on a block corner.
std::vector<MarkObject> objects(const terrain::HeightField& g) {
  MarkObject ball;
  ball.name = "ball";
  ball.mesh = testing::sphere(0.1);
  ball.follow_ground = true;
  for (int k = 0; k <= 11; ++k)
    ball.trajectory.keys.push_back({0.1 * k, world(g, 20 + 10 * k, 40 + 2 * k, 0.1 - 0.02)});
  MarkObject box;
  box.name = "box";
  box.mesh = testing::box(0.06, 0.05, 0.05);
  box.material = *material_preset("mud");
  const double top = 1.0 + 0.05;
  box.trajectory.keys = {{0.0, world(g, 96, 64, top + 0.01)},
                         {0.3, world(g, 96, 64, top - 0.02)},
                         {0.6, world(g, 96, 64, top - 0.02)},
                         {0.7, world(g, 96, 64, top + 0.2)},
                         {1.1, world(g, 96, 64, top + 0.2)}};
  return {ball, box};
}

std::size_t differing(const terrain::Grid<float>& a, const terrain::Grid<float>& b) {
  EXPECT_EQ(a.width(), b.width());
  EXPECT_EQ(a.height(), b.height());
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.values().size(); ++i)
    n += std::memcmp(&a.values()[i], &b.values()[i], sizeof(float)) != 0;
  return n;
}

struct BlockRun {
  terrain::HeightField heights, disturbed;
  MarksBlockReport report;
};

BlockRun by_blocks(const std::filesystem::path& dir, const terrain::HeightField& ground, int block,
                   int halo) {
  terrain::write_geotiff(ground, dir / "ground.tif");
  MarksBlockFiles files{dir / "ground.tif", dir / "out.tif", dir / "dist.tif", block, halo};
  BlockRun r;
  r.report = marks_to_files(files, objects(ground), *material_preset("sand"), {});
  r.heights = terrain::read_raster(dir / "out.tif");
  r.disturbed = terrain::read_raster(dir / "dist.tif");
  return r;
}

TEST(MarksBlocks, SmallBlocksGiveTheOnePassRunBitForBit) {
  const terrain::HeightField ground = rolling();
  const MarksResult one = simulate_marks(ground, objects(ground), testing::only("sand"), {});
  const BlockRun blocks = by_blocks(drift::testing::test_dir("marks_blocks"), ground, 32, 16);
  // The run marked the ground (else equality says nothing).
  std::size_t marked = 0;
  for (std::size_t i = 0; i < ground.values().size(); ++i)
    marked += one.heights.values()[i] != ground.values()[i];
  EXPECT_GT(marked, 1000u);
  EXPECT_EQ(differing(one.heights, blocks.heights), 0u) << "heights";
  EXPECT_EQ(differing(one.disturbed, blocks.disturbed), 0u) << "disturbance";
  EXPECT_EQ(blocks.report.blocks, 28);  // 7 x 4 blocks of 32
  EXPECT_GT(blocks.report.simulated, 1);
  EXPECT_LT(blocks.report.simulated, blocks.report.blocks);  // the far corners were copied
  // Both objects touched the ground, as in one pass.
  for (std::size_t k = 0; k < 2; ++k)
    EXPECT_GT(blocks.report.report.objects[k].contact_steps, 0) << k;
}

TEST(MarksBlocks, AHaloTooNarrowIsWidenedAndStillGivesTheSameBits) {
  const terrain::HeightField ground = rolling();
  const MarksResult one = simulate_marks(ground, objects(ground), testing::only("sand"), {});
  const BlockRun blocks = by_blocks(drift::testing::test_dir("marks_blocks"), ground, 32, 0);
  EXPECT_GT(blocks.report.widened, 0);  // rims reached beyond a bare block
  EXPECT_EQ(differing(one.heights, blocks.heights), 0u) << "heights";
  EXPECT_EQ(differing(one.disturbed, blocks.disturbed), 0u) << "disturbance";
}

}  // namespace
}  // namespace drift::marks
