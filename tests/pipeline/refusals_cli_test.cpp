// The number, size and input classes of docs/outputs.md, per subcommand: NaN
// and infinity are usage errors (exit 2) naming the flag; values whose use would
// overflow, crops of no area and latitudes off the globe are errors naming the
// value; sizes are checked against memory before anything is allocated (the
// message says how much is needed and how much there is); FIFOs as inputs fail
// at once rather than hang. Existing outputs are untouched in every case.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "render/image.h"
#include "render/image_io.h"
#include "terrain/raster_io.h"
#include "tests/cli_fixture.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;

namespace {

using namespace drift::testing;
using Result = RunResult;

fs::path test_dir() { return drift::testing::test_dir("drift_refusals_cli"); }

// Runs drift (at most 60 s: a hang fails the test rather than the suite) with
// the environment assignments in `env` and returns its status and output.
Result drift(const std::string& args, const fs::path& d, const std::string& env = "") {
  const fs::path log = d / "log.txt";
  const std::string cmd =
      env + " timeout 60 " + DRIFT_EXECUTABLE + " " + args + " > " + log.string() + " 2>&1";
  const int raw = std::system(cmd.c_str());
  return {WEXITSTATUS(raw), slurp(log)};
}

// A small metric DEM, `value` at cell (3, 2).
fs::path dem(const fs::path& d, float value = 1.0f, double cell = 10.0) {
  drift::terrain::HeightField g(16, 16, 100.0f, drift::terrain::local_georeference(cell));
  g(3, 2) = value;
  const fs::path p = d / "dem.tif";
  drift::terrain::write_geotiff(g, p);
  return p;
}

// A small soil scenario: a column of sand on the grid's floor.
const char* kSoilScenario =
    "[grid]\nsize = [16, 16, 16]\nvoxel = 0.1\n[simulation]\nsteps = 5\n"
    "[[soil_body]]\n[[soil_body.primitive]]\nshape = \"cylinder\"\ncenter = [0.8, 0.8, 0.6]\n"
    "radius = 0.3\nhalf_height = 0.4\n";

// A ball pressed into the middle of dem(): keyframes at 0 and `end` seconds.
std::string ball_track(double end, double step) {
  auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", v);
    return std::string(text);
  };
  return "step = " + number(step) +
         "\n[[objects]]\nmesh = \"" DRIFT_SOURCE_DIR
         "/data/objects/ball.obj\"\nscale = 5\n"
         "[[objects.keyframes]]\ntime = 0\nposition = [80, -80, 103]\n"
         "[[objects.keyframes]]\ntime = " +
         number(end) + "\nposition = [80, -80, 99]\n";
}

#define EXPECT_REFUSED(result, code, needle)                        \
  do {                                                              \
    const Result r_ = (result);                                     \
    EXPECT_EQ(r_.status, code) << r_.log;                           \
    EXPECT_NE(r_.log.find(needle), std::string::npos) << r_.log;    \
    EXPECT_NE(r_.log.find("drift: "), std::string::npos) << r_.log; \
  } while (0)

TEST(RefusalsCli, NonFiniteNumbersAreUsageErrorsInEverySubcommand) {
  const fs::path d = test_dir(), in = dem(d), out = d / "out.tif";
  put(out, "old");
  const std::string i = in.string(), o = " -o " + out.string();
  const std::string png = (d / "a.png").string();
  put(d / "scene.toml", "[terrain]\nraster = \"dem.tif\"\n");
  const std::string scene = (d / "scene.toml").string();
  put(d / "soil.toml", kSoilScenario);
  put(d / "track.toml", ball_track(160.0, 0.1));
  const std::string soil = "soil " + (d / "soil.toml").string() + " -o " + (d / "s.ply").string();
  const std::string marks = "marks " + i + " --track " + (d / "track.toml").string() + o;
  for (const std::string& args : {
           "import " + i + o + " --resample nan",
           "import " + i + o + " --exaggerate inf",
           "import " + i + o + " --crop 0,0,nan,10",
           "dunes --size 16 --cell nan" + o,
           "snow cover " + i + o + " --snow-line nan",
           "snow cover " + i + o + " --radius inf",
           "snow fall " + i + o + " --rate nan",
           "snow fall " + i + o + " --direction 0,nan",
           "render " + scene + " -o " + png + " --exposure nan",
           "render " + scene + " -o " + png + " --noise-target nan",
           "merge " + png + " -o " + png + " --exposure -inf",
           "compare " + png + " " + png + " --pixel-threshold nan",
           "compare " + png + " " + png + " --threshold inf",
           "sheet " + png + " -o " + png + " --exposure nan",
           soil + " --phi nan",
           soil + " --cohesion inf",
           soil + " --moisture nan",
           soil + " --gamma -inf",
           marks + " --snow-min nan",
           marks + " --snow-min inf",
       }) {
    const Result r = drift(args, d);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.log;
    // (An option's own range check may refuse inf first, with its own words.)
    if (args.find("nan") != std::string::npos) {
      EXPECT_NE(r.log.find("not a finite number"), std::string::npos) << args << "\n" << r.log;
    }
  }
  EXPECT_EQ(slurp(out), "old");
}

TEST(RefusalsCli, FifosAsInputsFailAtOnce) {
  const fs::path d = test_dir(), fifo = d / "pipe.tif";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  const std::string f = fifo.string(), o = " -o " + (d / "o.tif").string();
  for (const std::string& args :
       {"info " + f, "import " + f + o, "snow cover " + f + o, "render " + f + " -o x.png",
        "compare " + f + " " + f, "snow fall " + dem(d).string() + " --objects " + f + o}) {
    EXPECT_REFUSED(drift(args, d), 1, "pipe.tif");
  }
}

// Files named inside inputs are inputs too: a VRT's sources (a FIFO would
// block info and import for ever) and an OBJ's mtllib (/dev/zero would be read
// without end, a FIFO would block marks and snow fall).
TEST(RefusalsCli, FilesNamedInsideInputsObeyTheInputRules) {
  const fs::path d = test_dir(), fifo = d / "pipe.tif";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  const std::string vrt_head =
      "<VRTDataset rasterXSize=\"16\" rasterYSize=\"16\">\n"
      "<VRTRasterBand dataType=\"Float32\" band=\"1\"><SimpleSource>\n";
  const std::string vrt_tail =
      "<SourceBand>1</SourceBand></SimpleSource></VRTRasterBand></VRTDataset>\n";
  put(d / "fifo.vrt",
      vrt_head + "<SourceFilename relativeToVRT=\"1\">pipe.tif</SourceFilename>" + vrt_tail);
  put(d / "nested.vrt",
      vrt_head + "<SourceFilename relativeToVRT=\"1\">fifo.vrt</SourceFilename>" + vrt_tail);
  put(d / "device.vrt",
      vrt_head + "<SourceFilename relativeToVRT=\"0\">/dev/zero</SourceFilename>" + vrt_tail);
  const std::string o = " -o " + (d / "o.tif").string();
  for (const char* vrt : {"fifo.vrt", "nested.vrt"}) {
    const std::string v = (d / vrt).string();
    EXPECT_REFUSED(drift("info " + v, d), 1, "pipe.tif");
    EXPECT_REFUSED(drift("import " + v + o, d), 1, "pipe.tif");
  }
  EXPECT_REFUSED(drift("info " + (d / "device.vrt").string(), d), 1, "/dev/zero");
  // A VRT of a regular file still reads.
  dem(d);
  put(d / "good.vrt",
      vrt_head + "<SourceFilename relativeToVRT=\"1\">dem.tif</SourceFilename>" + vrt_tail);
  EXPECT_EQ(drift("info " + (d / "good.vrt").string(), d).status, 0);
  // An OBJ whose mtllib is a FIFO or /dev/zero reads as the mesh it is.
  put(d / "fifo.obj", "mtllib pipe.tif\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  put(d / "zero.obj",
      "mtllib ../../../../../../../../../dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  for (const char* obj : {"fifo.obj", "zero.obj"}) {
    put(d / "objects.toml",
        std::string("[[objects]]\nmesh = \"") + obj + "\"\nposition = [80, -80, 100]\n");
    EXPECT_EQ(drift("snow fall " + (d / "dem.tif").string() + " --maps 1 --spread 0 --objects " +
                        (d / "objects.toml").string() + o,
                    d)
                  .status,
              0)
        << obj;
  }
}

TEST(RefusalsCli, ImportRefusesEmptyCropsLatitudesOffTheGlobeAndHugeGrids) {
  const fs::path d = test_dir(), in = dem(d), out = d / "out.tif";
  put(out, "old");
  const std::string base = "import " + in.string() + " -o " + out.string();
  EXPECT_REFUSED(drift(base + " --crop 10,0,10,50", d), 1, "no area");
  EXPECT_REFUSED(drift(base + " --crop-lonlat 137,30,138,95", d), 1, "[-90, 90]");
  EXPECT_REFUSED(drift(base + " --crop-lonlat 137,36,137,37", d), 1, "west < east");
  // 160 m x 160 m at 1 mm cells: 2.56e10 cells, refused before GDAL allocates.
  EXPECT_REFUSED(drift(base + " --resample 0.001", d), 1, "too large a grid");
  EXPECT_REFUSED(drift(base + " --resample 0.01", d, "DRIFT_MEMORY_LIMIT=64M"), 1, "is available");
  EXPECT_EQ(slurp(out), "old");
}

// A pixel-interleaved TIFF of 63,233 bands: GDAL reads a row across all of
// them (1.3 GiB) to give one row of band 1; every reader checks that first.
TEST(RefusalsCli, RowAcrossEveryBandIsCheckedBeforeReading) {
  const fs::path d = test_dir();
  const std::string bands =
      DRIFT_SOURCE_DIR "/tests/fuzz/regressions/raster/row_across_63233_bands.tif";
  EXPECT_REFUSED(drift("info " + bands, d, "DRIFT_MEMORY_LIMIT=64M"), 1, "across its 63233 bands");
}

// An empty value, as an unset shell variable gives, is a usage error naming
// the option: `snow fall --cover ""` wrote no cover and `render --terrain ""`
// rendered the scene's own raster, both with exit 0.
TEST(RefusalsCli, EmptyValuesAreUsageErrors) {
  const fs::path d = test_dir(), in = dem(d), out = d / "out.tif";
  put(out, "old");
  const std::string i = in.string(), o = " -o " + out.string();
  put(d / "scene.toml", "[terrain]\nraster = \"dem.tif\"\n");
  const std::string render = "render " + (d / "scene.toml").string() + " --size 16x8 --spp 1 ";
  const std::pair<std::string, std::string> runs[] = {
      {"snow fall " + i + " --maps 1 --cover \"\"" + o, "--cover is empty"},
      {"snow fall " + i + " --maps 1 --objects \"\"" + o, "--objects is empty"},
      {render + "--terrain \"\" -o " + (d / "a.png").string(), "--terrain is empty"},
      {render + "--snow-depth \"\" -o " + (d / "a.png").string(), "--snow-depth is empty"},
      {"snow cover " + i + " --descriptor \"\"" + o, "--descriptor is empty"},
      {"info \"\"", "raster argument is empty"},
  };
  for (const auto& [args, needle] : runs) EXPECT_REFUSED(drift(args, d), 2, needle);
  EXPECT_EQ(slurp(out), "old");
  EXPECT_FALSE(fs::exists(d / "a.png"));
  // Free text may be empty: a sheet without a title.
  EXPECT_EQ(drift(render + "-o " + (d / "a.png").string(), d).status, 0);
  EXPECT_EQ(
      drift("sheet " + (d / "a.png").string() + " --title \"\" -o " + (d / "sheet.png").string(), d)
          .status,
      0);
}

TEST(RefusalsCli, RastersWithInfiniteCellsOrCellSizesAreRefused) {
  const fs::path d = test_dir(), out = d / "out.tif";
  const std::string o = " -o " + out.string();
  const std::string inf_dem = dem(d, std::numeric_limits<float>::infinity()).string();
  EXPECT_REFUSED(drift("info " + inf_dem, d), 1, "infinite height");
  EXPECT_REFUSED(drift("snow cover " + inf_dem + o, d), 1, "column 3, row 2");
  drift::terrain::HeightField g(8, 8, 1.0f, drift::terrain::local_georeference(0.0));
  drift::terrain::write_geotiff(g, d / "flat.tif");
  EXPECT_REFUSED(drift("import " + (d / "flat.tif").string() + o, d), 1, "georeference");
  EXPECT_FALSE(fs::exists(out));
}

// A finite height no ground has, such as an undeclared nodata of -3.4e38 or a
// snow depth of 1e30 m, is refused like an infinite one: the render of such a
// raster came out black with exit 0 (the ray tracer's arithmetic overflows).
TEST(RefusalsCli, RastersWithHeightsBeyondAnyGroundAreRefused) {
  const fs::path d = test_dir(), out = d / "out.png";
  const std::string huge = dem(d, -3.4e38f).string();
  EXPECT_REFUSED(drift("info " + huge, d), 1, "column 3, row 2");
  drift::terrain::HeightField depth(16, 16, 0.2f, drift::terrain::local_georeference(10.0));
  depth(5, 4) = 1e30f;
  drift::terrain::write_geotiff(depth, d / "depth.tif");
  fs::copy_file(dem(d, 100.0f), d / "ground.tif");
  put(d / "scene.toml", "[terrain]\nraster = \"ground.tif\"\n");
  EXPECT_REFUSED(
      drift("render " + (d / "scene.toml").string() + " --size 16x8 --spp 1 --snow-depth " +
                (d / "depth.tif").string() + " -o " + out.string(),
            d),
      1, "depth.tif' holds a height of 1e+30 at column 5, row 4");
  EXPECT_FALSE(fs::exists(out));
  // Within the bound (10,000 km: heights in millimetres still fit), it is read.
  EXPECT_EQ(drift("info " + dem(d, 9.9e6f).string(), d).status, 0);
}

TEST(RefusalsCli, SceneValuesWhoseReciprocalsOverflowAndLatitudesOffTheGlobe) {
  const fs::path d = test_dir();
  dem(d);
  drift::terrain::HeightField ripples(16, 16, 0.0f, drift::terrain::local_georeference(0.01));
  drift::terrain::write_geotiff(ripples, d / "ripples.tif");
  const std::string head = "[terrain]\nraster = \"dem.tif\"\n";
  const std::string render =
      "render " + (d / "scene.toml").string() + " --size 8x4 --spp 1 -o " + (d / "a.png").string();
  put(d / "scene.toml", head + "[ripples]\nraster = \"ripples.tif\"\ncell = 1e-39\n");
  EXPECT_REFUSED(drift(render, d), 1, "ripples.cell");
  put(d / "scene.toml", head + "[camera]\nfrom_lonlat = [137.6, 95.0]\nto = [80, -80, 100]\n");
  EXPECT_REFUSED(drift(render, d), 1, "[-90, 90]");
  put(d / "scene.toml", head +
                            "[camera]\nfrom = [0, 0, 500]\nto = [80, -80, 100]\n"
                            "focal_length = 1e-30\n");
  EXPECT_REFUSED(drift(render, d), 1, "focal_length");
  EXPECT_FALSE(fs::exists(d / "a.png"));
}

TEST(RefusalsCli, SizesAreCheckedAgainstMemoryBeforeAllocating) {
  const fs::path d = test_dir();
  dem(d);
  put(d / "scene.toml", "[terrain]\nraster = \"dem.tif\"\n");
  // A render's image.
  EXPECT_REFUSED(drift("render " + (d / "scene.toml").string() + " --size 16384x16384 -o " +
                           (d / "a.exr").string(),
                       d, "DRIFT_MEMORY_LIMIT=1G"),
                 1, "needs");
  // An image declaring 60000^2 pixels in 69 bytes, before decoding.
  const std::string huge =
      std::string(DRIFT_SOURCE_DIR) + "/tests/fuzz/regressions/image/declares_60000x60000.png";
  EXPECT_REFUSED(drift("compare " + huge + " " + huge, d), 1, "60000x60000");
  EXPECT_REFUSED(drift("sheet " + huge + " -o " + (d / "s.png").string(), d), 1, "60000x60000");
  // A sheet title far wider than any sheet.
  ASSERT_EQ(drift("render " + (d / "scene.toml").string() + " --size 8x4 --spp 1 -o " +
                      (d / "small.png").string(),
                  d)
                .status,
            0);
  EXPECT_REFUSED(drift("sheet " + (d / "small.png").string() + " --font-size 128 --title " +
                           std::string(20000, 'W') + " -o " + (d / "s.png").string(),
                       d),
                 1, "the title");
  // One big triangle refined for snowfall.
  put(d / "tri.obj", "v 0 0 0\nv 1000 0 0\nv 0 1000 0\nf 1 2 3\n");
  put(d / "objects.toml", "[[objects]]\nmesh = \"tri.obj\"\nposition = [80, -80, 100]\n");
  EXPECT_REFUSED(drift("snow fall " + (d / "dem.tif").string() + " --objects " +
                           (d / "objects.toml").string() + " --mesh-edge 0.001 -o " +
                           (d / "depth.tif").string(),
                       d),
                 1, "--mesh-edge");
  EXPECT_FALSE(fs::exists(d / "depth.tif") || fs::exists(d / "s.png"));
}

// DRIFT_MEMORY_LIMIT is read strictly, in every subcommand, before any work:
// "1T" had read as 1 byte, "8 G" as 8 bytes, and "abc", "0", "-5", "nan" as no cap.
TEST(RefusalsCli, MalformedMemoryLimitIsAUsageErrorNamingTheVariable) {
  const fs::path d = test_dir(), in = dem(d), out = d / "out.tif";
  put(out, "old");
  for (const char* bad : {"abc", "0", "-5", "nan", "'8 G'", "1X"}) {
    for (const std::string& args :
         {"info " + in.string(), "import " + in.string() + " -o " + out.string()}) {
      EXPECT_REFUSED(drift(args, d, std::string("DRIFT_MEMORY_LIMIT=") + bad), 2,
                     "DRIFT_MEMORY_LIMIT is");
    }
  }
  EXPECT_EQ(slurp(out), "old");
  // The documented forms work, "1T" as a terabyte rather than a byte.
  for (const char* good : {"1T", "1TiB", "8G", "4096M", ""}) {
    EXPECT_EQ(drift("info " + in.string(), d, std::string("DRIFT_MEMORY_LIMIT=") + good).status, 0)
        << good;
  }
}

TEST(RefusalsCli, SoilRefusesValuesOutOfRangeAndGridsLargerThanMemory) {
  const fs::path d = test_dir(), out = d / "soil.ply";
  put(out, "old");
  const std::string run = "soil " + (d / "s.toml").string() + " -o " + out.string();
  const std::string base = kSoilScenario;
  const struct {
    std::string from, to, needle;
  } cases[] = {
      {"voxel = 0.1", "voxel = 1e-39", "voxel"},
      {"voxel = 0.1", "voxel = inf", "voxel"},
      {"steps = 5", "steps = 5\ndt = nan", "dt"},
      {"radius = 0.3", "radius = 1e300", "radius"},
      {"size = [16, 16, 16]", "size = [16, 16, 100000]", "size"},
  };
  for (const auto& c : cases) {
    std::string text = base;
    text.replace(text.find(c.from), c.from.size(), c.to);
    put(d / "s.toml", text);
    EXPECT_REFUSED(drift(run, d), 1, c.needle);
    EXPECT_NE(drift(run, d).log.find("s.toml"), std::string::npos) << c.to;
  }
  // 512^3 voxels: the state is checked against memory before it is allocated.
  std::string big = base;
  big.replace(big.find("[16, 16, 16]"), 12, "[512, 512, 512]");
  put(d / "s.toml", big);
  EXPECT_REFUSED(drift(run, d, "DRIFT_MEMORY_LIMIT=256M"), 1, "is available");
  EXPECT_REFUSED(drift(run + " --steps 2000000000", d), 2, "--steps");
  // The --ground raster, widened by --ground-margin, is checked before the work.
  put(d / "s.toml", base);
  const std::string ground = run + " --ground " + (d / "g.tif").string();
  EXPECT_REFUSED(drift(ground + " --ground-margin 50000", d, "DRIFT_MEMORY_LIMIT=256M"), 1,
                 "--ground raster of 100016 x 100016 cells");
  EXPECT_REFUSED(drift(ground + " --ground-margin -5", d), 2, "--ground-margin");
  // --frames must name a directory: a file is not one, and the message says so
  // (not "does not exist").
  put(d / "afile", "keep");
  EXPECT_REFUSED(drift(run + " --frames " + (d / "afile").string(), d), 1, "is not a directory");
  EXPECT_REFUSED(drift(run + " --frames " + (d / "none").string(), d), 1, "does not exist");
  EXPECT_EQ(slurp(out), "old");
  EXPECT_EQ(slurp(d / "afile"), "keep");
  EXPECT_FALSE(fs::exists(d / "g.tif"));
}

// "wrote" is printed for outputs only once they are all in place: a failure
// while the second output is made leaves the first unreplaced and unreported.
TEST(RefusalsCli, SoilReportsOnlyCommittedOutputs) {
  const fs::path d = test_dir(), out = d / "soil.ply";
  put(out, "old");
  put(d / "s.toml", kSoilScenario);  // no terrain, no bodies: no --collision mesh
  const Result r = drift("soil " + (d / "s.toml").string() + " -o " + out.string() +
                             " --collision " + (d / "bodies.ply").string(),
                         d);
  EXPECT_EQ(r.status, 1) << r.log;
  EXPECT_NE(r.log.find("--collision"), std::string::npos) << r.log;
  EXPECT_EQ(r.log.find("wrote"), std::string::npos) << r.log;
  EXPECT_EQ(slurp(out), "old");
  EXPECT_FALSE(fs::exists(d / "bodies.ply"));
}

TEST(RefusalsCli, MarksRefusesValuesOutOfRangeEndlessTracksAndGroundsLargerThanMemory) {
  const fs::path d = test_dir(), out = d / "out.tif";
  put(out, "old");
  const std::string run =
      "marks " + dem(d).string() + " --track " + (d / "t.toml").string() + " -o " + out.string();
  put(d / "t.toml", ball_track(1.0, 1e-300));
  EXPECT_REFUSED(drift(run, d), 1, "step");
  put(d / "t.toml", ball_track(1.0, std::numeric_limits<double>::infinity()));
  EXPECT_REFUSED(drift(run, d), 1, "t.toml");
  // 1e9 s at the smallest step: 1e15 steps, refused rather than run for ever.
  put(d / "t.toml", ball_track(1e9, 1e-6));
  EXPECT_REFUSED(drift(run, d), 1, "raise 'step'");
  put(d / "t.toml", ball_track(1.0, 0.1));
  EXPECT_REFUSED(drift(run + " --memory-steps 2000000", d), 2, "--memory-steps");
  // A 2048^2 ground needs ~120 MB of marks state: checked before allocating.
  drift::terrain::HeightField big(2048, 2048, 100.0f, drift::terrain::local_georeference(0.1));
  drift::terrain::write_geotiff(big, d / "big.tif");
  EXPECT_REFUSED(drift("marks " + (d / "big.tif").string() + " --track " + (d / "t.toml").string() +
                           " -o " + out.string(),
                       d, "DRIFT_MEMORY_LIMIT=64M"),
                 1, "marks state for a 2048 x 2048 ground");
  // --frames naming a file or a device: refused before any work, naming the flag.
  put(d / "afile", "keep");
  EXPECT_REFUSED(drift(run + " --frames " + (d / "afile").string(), d), 1,
                 "--frames '" + (d / "afile").string() + "' is not a directory");
  EXPECT_REFUSED(drift(run + " --frames /dev/null", d), 1,
                 "--frames '/dev/null' is not a directory");
  EXPECT_EQ(slurp(d / "afile"), "keep");
  EXPECT_EQ(slurp(out), "old");
}

TEST(RefusalsCli, NonFiniteMeshVerticesAreRefused) {
  const fs::path d = test_dir();
  put(d / "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  put(d / "objects.toml", "[[objects]]\nmesh = \"nan.obj\"\nposition = [80, -80, 100]\n");
  EXPECT_REFUSED(drift("snow fall " + dem(d).string() + " --objects " +
                           (d / "objects.toml").string() + " -o " + (d / "depth.tif").string(),
                       d),
                 1, "nan.obj");
}

TEST(RefusalsCli, TilesOfDifferentScenesDoNotMerge) {
  const fs::path d = test_dir();
  dem(d);
  put(d / "a.toml", "[terrain]\nraster = \"dem.tif\"\n[sun]\nelevation = 30\n");
  put(d / "b.toml", "[terrain]\nraster = \"dem.tif\"\n[sun]\nelevation = 60\n");
  for (const std::string tile : {"a 0", "b 1", "a 1"}) {
    const std::string scene(1, tile[0]), index(1, tile[2]);
    ASSERT_EQ(drift("render " + (d / (scene + ".toml")).string() + " --size 8x4 --spp 1 --tile " +
                        index + "/2 -o " + (d / (scene + index + ".exr")).string(),
                    d)
                  .status,
              0);
  }
  const std::string a0 = (d / "a0.exr").string();
  EXPECT_REFUSED(
      drift("merge " + a0 + " " + (d / "b1.exr").string() + " -o " + (d / "m.exr").string(), d), 1,
      "another scene");
  EXPECT_EQ(
      drift("merge " + a0 + " " + (d / "a1.exr").string() + " -o " + (d / "m.exr").string(), d)
          .status,
      0);
}

// compare --region X,Y,W,H: numbers an int cannot hold are usage errors (read
// modulo 2^32, 4294967296 would compare column 0), and a rectangle whose far
// edge overflows an int is outside the image (wrapped past the check, it would
// read beyond the pixels).
TEST(RefusalsCli, CompareRegionsBeyondAnIntOrTheImageAreRefused) {
  const fs::path d = test_dir();
  const std::string png = (d / "a.png").string(), diff = (d / "diff.png").string();
  drift::render::write_image(drift::render::Image(8, 4, {"R", "G", "B"}, 0.5f), png);
  put(diff, "old");
  const std::string base = "compare " + png + " " + png + " --diff " + diff + " --region ";
  EXPECT_EQ(drift(base + "1,1,4,2", d).status, 0);
  for (const char* region : {"4294967296,0,1,1", "0,0,99999999999999999999,1", "0,0,nan,1", "0,0,1",
                             "0,0,1,1,1", "1.5,0,1,1"}) {
    SCOPED_TRACE(region);
    EXPECT_REFUSED(drift(base + region, d), 2, "--region");
  }
  EXPECT_REFUSED(drift(base + "2147483000,0,1000,1", d), 1, "not inside the 8x4 image");
  EXPECT_REFUSED(drift(base + "0,1,8,2147483647", d), 1, "not inside the 8x4 image");
  put(diff, "old");
  EXPECT_REFUSED(drift(base + "7,0,2,1", d), 1, "not inside the 8x4 image");
  EXPECT_EQ(slurp(diff), "old");
}

TEST(RefusalsCli, SceneOutputFilesResolveAgainstTheSceneFile) {
  const fs::path d = test_dir();
  fs::create_directories(d / "scenes");
  dem(d / "scenes");
  put(d / "scenes" / "s.toml",
      "[terrain]\nraster = \"dem.tif\"\n[render]\nwidth = 8\nheight = 4\nspp = 1\n"
      "[output]\nfiles = [\"out.png\"]\n");
  ASSERT_EQ(drift("render " + (d / "scenes" / "s.toml").string(), d).status, 0);
  EXPECT_TRUE(fs::exists(d / "scenes" / "out.png"));
}

TEST(RefusalsCli, StageFlagsNeedASectionOnlyWhereTheStageDoes) {
  // The stages' product flags come from pipeline/scene_products.h: --ripples
  // needs [ripples] (its look is set there), --snow-cover works without [snow].
  const fs::path d = test_dir();
  const std::string raster = dem(d).string();
  put(d / "s.toml", "[terrain]\nraster = \"dem.tif\"\n");
  const std::string render = "render " + (d / "s.toml").string() + " --size 8x4 --spp 1 -o ";
  EXPECT_REFUSED(drift(render + (d / "r.png").string() + " --ripples " + raster, d), 1,
                 "--ripples needs a [ripples] section");
  EXPECT_FALSE(fs::exists(d / "r.png"));
  EXPECT_EQ(drift(render + (d / "c.png").string() + " --snow-cover " + raster, d).status, 0);
}

}  // namespace
