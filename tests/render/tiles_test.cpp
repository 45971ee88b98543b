// Tiles across machines: bands rendered separately and merged are the same
// bits as one render; a missing or doubled band is an error naming it.
#include "render/tiles.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "render/camera_setup.h"
#include "render/image_io.h"
#include "render/renderer.h"
#include "render/terrain_scene.h"
#include "terrain/error.h"
#include "terrain/raster_io.h"
#include "tests/render/render_fixtures.h"

using namespace drift::render;
namespace fs = std::filesystem;

namespace {

SceneInput hills() {
  SceneInput in;
  in.terrain = drift::terrain::HeightField(48, 48, 0.0f, drift::terrain::local_georeference(5.0));
  for (int r = 0; r < 48; ++r)
    for (int x = 0; x < 48; ++x)
      in.terrain(x, r) = static_cast<float>(30.0 * std::sin(x * 0.2) * std::cos(r * 0.15));
  in.sun.elevation_deg = 20.0;
  return in;
}

fs::path temp_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto dir = fs::temp_directory_path() / (std::string("drift_tiles_") + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The hills rendered whole at `width` x `height`, 4 spp, the one frame the
// tiles must merge back to, written to and read back from `dir`/whole.exr:
// through EXR files, as across machines (EXR sorts the channels by name).
struct WholeFrame {
  SceneInput in = hills();
  TerrainScene scene{in};
  Camera camera = default_camera(scene);
  RenderSettings rs;
  fs::path dir = temp_dir();
  Image whole;
  WholeFrame(int width, int height) : rs(drift::testing::frame_settings(width, height, 4)) {
    write_exr(render_image(scene, in, camera, rs), dir / "whole.exr");
    whole = read_image(dir / "whole.exr");
  }
};

}  // namespace

TEST(Tiles, RowsCoverTheFrameOnce) {
  for (int n : {1, 2, 3, 7, 90}) {
    int next = 0;
    for (int i = 0; i < n; ++i) {
      const RowRange r = tile_rows(90, i, n);
      EXPECT_EQ(r.begin, next);
      EXPECT_GT(r.end, r.begin);
      next = r.end;
    }
    EXPECT_EQ(next, 90);
  }
  EXPECT_THROW(tile_rows(90, 3, 3), drift::Error);
  EXPECT_THROW(tile_rows(10, 0, 11), drift::Error);
  EXPECT_THROW(parse_tile("3of4"), drift::Error);
  EXPECT_EQ(parse_tile("3/16"), std::make_pair(3, 16));
}

TEST(Tiles, BlocksCoverTheFrameOnce) {
  // "i/n" stays a band; "i/CxR" is block i of C columns and R rows, row by row.
  const TileSpec band = parse_tile_spec("3/16");
  EXPECT_EQ(band.index, 3);
  EXPECT_EQ(band.columns, 1);
  EXPECT_EQ(band.rows, 16);
  const TileSpec block = parse_tile_spec("5/4x3");
  EXPECT_EQ(block.index, 5);
  EXPECT_EQ(block.columns, 4);
  EXPECT_EQ(block.rows, 3);
  EXPECT_THROW(parse_tile_spec("12/4x3"), drift::Error);
  EXPECT_THROW(parse_tile_spec("0/0x3"), drift::Error);
  EXPECT_THROW(parse_tile_spec("1/4by3"), drift::Error);
  EXPECT_THROW(tile_rect(3, 90, {0, 4, 1}), drift::Error);  // more columns than pixels
  std::vector<int> owner(50 * 37, -1);
  for (int i = 0; i < 4 * 3; ++i) {
    const TileRect r = tile_rect(50, 37, {i, 4, 3});
    EXPECT_GT(r.x.end, r.x.begin);
    EXPECT_GT(r.y.end, r.y.begin);
    for (int y = r.y.begin; y < r.y.end; ++y)
      for (int x = r.x.begin; x < r.x.end; ++x) {
        EXPECT_EQ(owner[y * 50 + x], -1);
        owner[y * 50 + x] = i;
      }
  }
  EXPECT_EQ(std::count(owner.begin(), owner.end(), -1), 0);
  const TileRect last = tile_rect(50, 37, {11, 4, 3});
  EXPECT_EQ(last.x.end, 50);
  EXPECT_EQ(last.y.end, 37);
}

TEST(Tiles, MergedBlocksAreBitIdenticalToOneRender) {
  const WholeFrame f(41, 29);
  const auto& [in, scene, camera, rs, dir, whole] = f;
  std::vector<Image> tiles;
  std::vector<fs::path> names;
  for (int i : {4, 0, 2, 5, 1, 3}) {  // any order
    const TileRect r = tile_rect(rs.width, rs.height, {i, 3, 2});
    RenderSettings part = rs;
    part.row_begin = r.y.begin, part.row_end = r.y.end;
    part.col_begin = r.x.begin, part.col_end = r.x.end;
    names.push_back(dir / ("block" + std::to_string(i) + ".exr"));
    write_exr(render_image(scene, in, camera, part), names.back());
    tiles.push_back(read_image(names.back()));
    EXPECT_EQ(tiles.back().frame.x, r.x.begin);
    EXPECT_EQ(tiles.back().frame.y, r.y.begin);
  }
  const Image merged = merge_tiles(tiles, names);
  ASSERT_EQ(merged.channels, whole.channels);
  EXPECT_EQ(merged.pixels, whole.pixels);  // bit for bit
  // A missing block is named by its columns and row; a doubled one by its files.
  try {
    merge_tiles({tiles[0], tiles[1], tiles[2], tiles[3], tiles[4]},
                {names[0], names[1], names[2], names[3], names[4]});
    ADD_FAILURE() << "a missing block must be an error";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("columns 0 to 12 of row 14"), std::string::npos)
        << e.what();
  }
  try {
    std::vector<Image> doubled = tiles;
    doubled.push_back(tiles[2]);
    std::vector<fs::path> doubled_names = names;
    doubled_names.push_back(dir / "again.exr");
    merge_tiles(doubled, doubled_names);
    ADD_FAILURE() << "a doubled block must be an error";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("overlap"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(Tiles, MergedBandsAreBitIdenticalToOneRender) {
  const WholeFrame f(40, 30);
  const auto& [in, scene, camera, rs, dir, whole] = f;
  std::vector<Image> tiles;
  std::vector<fs::path> names;
  for (int i : {2, 0, 1}) {  // any order
    const RowRange rows = tile_rows(rs.height, i, 3);
    RenderSettings part = rs;
    part.row_begin = rows.begin;
    part.row_end = rows.end;
    Image tile = render_image(scene, in, camera, part);
    tile.attributes = {{"exposure", "-1.5"}};
    names.push_back(dir / ("tile" + std::to_string(i) + ".exr"));
    write_exr(tile, names.back());
    tiles.push_back(read_image(names.back()));
    EXPECT_EQ(tiles.back().frame.y, rows.begin);
    EXPECT_EQ(tiles.back().frame.full_height, rs.height);
  }
  const Image merged = merge_tiles(tiles, names);
  ASSERT_EQ(merged.width, whole.width);
  ASSERT_EQ(merged.height, whole.height);
  ASSERT_EQ(merged.channels, whole.channels);
  EXPECT_EQ(merged.pixels, whole.pixels);  // bit for bit
  ASSERT_NE(merged.attribute("exposure"), nullptr);
  EXPECT_EQ(*merged.attribute("exposure"), "-1.5");

  // A missing band is named by its rows; a doubled one by its files.
  try {
    merge_tiles({tiles[0], tiles[2]}, {names[0], names[2]});
    ADD_FAILURE() << "a missing tile must be an error";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("rows 0 to 9"), std::string::npos) << e.what();
  }
  EXPECT_THROW(merge_tiles({tiles[0], tiles[0], tiles[1], tiles[2]},
                           {names[0], names[0], names[1], names[2]}),
               drift::Error);
  EXPECT_THROW(merge_tiles({whole}, {"whole.exr"}), drift::Error);
  fs::remove_all(dir);
}

TEST(Tiles, CommandLineTilesMergeToTheSingleRun) {
  const fs::path dir = temp_dir();
  drift::terrain::write_geotiff(hills().terrain, dir / "dem.tif");
  std::ofstream(dir / "s.toml") << "[terrain]\nraster = \"dem.tif\"\n"
                                   "[render]\nwidth = 32\nheight = 20\nspp = 2\n";
  const std::string drift = DRIFT_EXECUTABLE;
  auto run = [&](const std::string& args) {
    return std::system((drift + " " + args + " > /dev/null 2>&1").c_str());
  };
  const std::string scene = (dir / "s.toml").string();
  ASSERT_EQ(run("render " + scene + " -o " + (dir / "whole.exr").string()), 0);
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(run("render " + scene + " --tile " + std::to_string(i) + "/4 -o " +
                  (dir / ("t" + std::to_string(i) + ".exr")).string()),
              0);
  }
  EXPECT_NE(run("render " + scene + " --tile 0/4 -o " + (dir / "t.png").string()), 0);
  EXPECT_NE(run("render " + scene + " --tile 4/4 -o " + (dir / "t.exr").string()), 0);
  const std::string tiles = (dir / "t0.exr").string() + " " + (dir / "t1.exr").string() + " " +
                            (dir / "t2.exr").string() + " " + (dir / "t3.exr").string();
  ASSERT_EQ(run("merge " + tiles + " -o " + (dir / "merged.exr").string() + " -o " +
                (dir / "merged.png").string()),
            0);
  EXPECT_TRUE(fs::exists(dir / "merged.png"));
  EXPECT_EQ(read_image(dir / "merged.exr").pixels, read_image(dir / "whole.exr").pixels);
  // Without the last tile: exit 1, and no output written.
  EXPECT_EQ(run("merge " + (dir / "t0.exr").string() + " -o " + (dir / "part.exr").string()), 256);
  EXPECT_FALSE(fs::exists(dir / "part.exr"));
  fs::remove_all(dir);
}

// The documented GNU parallel command (docs/rendering.md, "Tiles across
// machines"): n local processes render the blocks of a 3x2 grid, drift merge
// joins them, and the frame is the single run's, bit for bit.
TEST(Tiles, GnuParallelBlocksMergeToTheSingleRun) {
  ASSERT_EQ(std::system("command -v parallel > /dev/null 2>&1"), 0)
      << "GNU parallel is missing: run scripts/install-deps.sh (Debian package parallel)";
  const fs::path dir = temp_dir();
  drift::terrain::write_geotiff(hills().terrain, dir / "dem.tif");
  std::ofstream(dir / "s.toml") << "[terrain]\nraster = \"dem.tif\"\n"
                                   "[render]\nwidth = 37\nheight = 23\nspp = 2\n";
  const std::string drift = DRIFT_EXECUTABLE;
  const std::string scene = (dir / "s.toml").string();
  ASSERT_EQ(std::system((drift + " render " + scene + " -o " + (dir / "whole.exr").string() +
                         " > /dev/null 2>&1")
                            .c_str()),
            0);
  const std::string command =
      "cd " + dir.string() + " && seq 0 5 | parallel --halt now,fail=1 -j 3 " + drift +
      " render s.toml --tile {}/3x2 -o part_{}.exr --threads 1" + " > /dev/null 2>&1 && " + drift +
      " merge part_*.exr -o frame.exr > /dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const Image frame = read_image(dir / "frame.exr");
  const Image whole = read_image(dir / "whole.exr");
  ASSERT_EQ(frame.channels, whole.channels);
  EXPECT_EQ(frame.pixels, whole.pixels);
  fs::remove_all(dir);
}
