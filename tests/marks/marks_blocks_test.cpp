// Marks block by block (terrain/marks/marks_blocks.h, issue 36 item 3): a
// ground cut artificially into small blocks, each worked on its window, gives
// the one-pass run's heights and disturbance bit for bit, whether the halo
// was wide enough at once or had to be doubled, and blocks no object comes
// near are copied as they are.
#include "terrain/marks/marks_blocks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "terrain/error.h"
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
                   int halo, MarksBlockFiles files = {}) {
  terrain::write_geotiff(ground, dir / "ground.tif");
  files.ground = dir / "ground.tif", files.output = dir / "out.tif";
  files.disturbed = dir / "dist.tif", files.block = block, files.halo = halo;
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
  // Both objects touched the ground, in as many steps as in one pass, and
  // the volumes are the one-pass run's: each object's step counted once, from
  // a window that holds it whole, added in the same order (overlapping
  // windows run the same steps; the busiest block's count was reported).
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_GT(blocks.report.report.objects[k].contact_steps, 0) << k;
    EXPECT_EQ(blocks.report.report.objects[k].contact_steps, one.report.objects[k].contact_steps)
        << k;
  }
  EXPECT_EQ(blocks.report.report.contact_steps, one.report.contact_steps);
  EXPECT_GT(one.report.collided, 0.0);
  EXPECT_EQ(blocks.report.report.collided, one.report.collided);
  EXPECT_EQ(blocks.report.report.displaced, one.report.displaced);
  EXPECT_EQ(blocks.report.report.compressed, one.report.compressed);
}

// Per-region materials block by block (--materials, --snow-depth): each
// window reads its cells' materials through GDAL as it reads the ground, and
// gives the one-pass run's bits: the ball drags through sand into mud, the
// mud box stands where the raster says snow.
TEST(MarksBlocks, MaterialRastersGiveTheOnePassRunBitForBit) {
  const terrain::HeightField ground = rolling();
  const auto dir = drift::testing::test_dir("marks_blocks_materials");
  terrain::HeightField indices(kWidth, kHeight, 0.0f, ground.geo());
  terrain::HeightField depth(kWidth, kHeight, 0.0f, ground.geo());
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      indices(x, y) = x < 70 ? 0.0f : x < 150 ? 1.0f : 2.0f;
      if (y > 58 && x > 85 && x < 110) indices(x, y) = 2.0f;
      depth(x, y) = (x >= 60 && x < 120 && y < 56) ? 0.05f : 0.0f;
    }
  terrain::write_geotiff(indices, dir / "materials.tif");
  terrain::write_geotiff(depth, dir / "depth.tif");
  std::vector<Material> table;
  for (const char* name : {"sand", "mud", "snow"}) table.push_back(*material_preset(name));
  {
    const MarksResult one =
        simulate_marks(ground, objects(ground), materials_from_raster(indices, table, "m"), {});
    const MarksResult sand = simulate_marks(ground, objects(ground), testing::only("sand"), {});
    EXPECT_GT(differing(one.heights, sand.heights), 100u);  // the materials matter
    MarksBlockFiles f;
    f.materials = dir / "materials.tif";
    const BlockRun blocks = by_blocks(dir, ground, 32, 16, f);
    EXPECT_EQ(differing(one.heights, blocks.heights), 0u) << "heights, --materials";
    EXPECT_EQ(differing(one.disturbed, blocks.disturbed), 0u) << "disturbance, --materials";
    EXPECT_GT(blocks.report.simulated, 1);
  }
  {
    const Material sand = *material_preset("sand"), snow = *material_preset("snow");
    const MarksResult one = simulate_marks(ground, objects(ground),
                                           materials_from_snow_depth(depth, 0.01, sand, snow), {});
    MarksBlockFiles f;
    f.snow_depth = dir / "depth.tif", f.snow_min = 0.01;
    const BlockRun blocks = by_blocks(dir, ground, 32, 16, f);
    EXPECT_EQ(differing(one.heights, blocks.heights), 0u) << "heights, --snow-depth";
    EXPECT_EQ(differing(one.disturbed, blocks.disturbed), 0u) << "disturbance, --snow-depth";
  }
}

// A material raster's bad cell is named in the raster's own cells, not the
// window's: only the box (columns 63-130, rows 31-98 with its reach) is run,
// so every window that reads the cell starts away from the raster's corner.
TEST(MarksBlocks, ABadMaterialCellIsNamedInTheRastersCells) {
  const terrain::HeightField ground = rolling();
  const auto dir = drift::testing::test_dir("marks_blocks_bad_material");
  terrain::write_geotiff(ground, dir / "ground.tif");
  terrain::HeightField indices(kWidth, kHeight, 0.0f, ground.geo());
  indices(100, 60) = 7.0f;
  terrain::write_geotiff(indices, dir / "materials.tif");
  MarksBlockFiles f;
  f.ground = dir / "ground.tif", f.output = dir / "out.tif", f.block = 32, f.halo = 16;
  f.materials = dir / "materials.tif";
  try {
    marks_to_files(f, {objects(ground)[1]}, *material_preset("sand"), {});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cell (100, 60) holds 7"), std::string::npos) << e.what();
  }
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
