// One validation idiom (issue 18): library code checks its options struct in
// validate() and speaks of fields; the command line maps the field to its flag.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "snow/snow_cover.h"
#include "snow/snowfall.h"
#include "terrain/import.h"
#include "terrain/parameter.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;

namespace {

// The library's message names `field` and no flag.
template <class Options>
void expect_field_error(const Options& o, const std::string& field) {
  try {
    o.validate();
    ADD_FAILURE() << field << " passed validate()";
  } catch (const drift::terrain::ParameterError& e) {
    EXPECT_EQ(e.field(), field);
    EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(OptionErrors, LibrarySpeaksOfFields) {
  drift::snow::CoverOptions cover;
  cover.region = 40;
  expect_field_error(cover, "region");
  drift::terrain::ImportOptions import;
  import.exaggeration = 0;
  expect_field_error(import, "exaggeration");
  drift::snow::SnowfallOptions fall;
  fall.spread_deg = 40;
  expect_field_error(fall, "spread_deg");
}

TEST(OptionErrors, CommandLineSpeaksOfFlags) {
  using drift::testing::drift_log;
  using drift::testing::run_drift;
  const fs::path d = drift::testing::test_dir("drift_option_errors");
  const std::string out = (d / "out.tif").string();
  EXPECT_EQ(run_drift("snow cover missing.tif -o " + out + " --region 40", d), 2);
  EXPECT_NE(drift_log(d).find("--region is 40; it must lie in (0, 32]"), std::string::npos)
      << drift_log(d);
  EXPECT_EQ(run_drift("snow fall missing.tif -o " + out + " --spread 40", d), 2);
  EXPECT_NE(drift_log(d).find("--spread is 40"), std::string::npos) << drift_log(d);
  EXPECT_EQ(run_drift("import missing.tif -o " + out + " --exaggerate 0", d), 1);
  EXPECT_NE(drift_log(d).find("--exaggerate is 0"), std::string::npos) << drift_log(d);
  EXPECT_EQ(run_drift("dunes --size 32 --L0 100 -o " + out, d), 2);
  EXPECT_NE(drift_log(d).find("--L0 is 100"), std::string::npos) << drift_log(d);
  EXPECT_FALSE(fs::exists(out));
}

// No value changed without a word, and messages that say what is wrong: "--seed
// -1", "2^64" and "1e23" had all become seed 2^64 - 1; "--spp 1e3" said "not in
// range" for "not a whole number"; "--size 100000x100000" said "must be
// WIDTHxHEIGHT" for "too large"; "--tile 3/3" exited 1 where "-1/3" exits 2.
TEST(OptionErrors, NumbersAreReadAsWrittenOrRefusedSayingWhy) {
  using drift::testing::drift_log;
  using drift::testing::run_drift;
  const fs::path d = drift::testing::test_dir("drift_option_numbers");
  const std::string out = (d / "out.tif").string();
  const std::string dunes = "dunes --size 16 --steps 1 -o " + out;
  for (const char* seed : {"-1", "18446744073709551616", "1e23", "0x10", "1.5"}) {
    EXPECT_EQ(run_drift(dunes + " --seed " + seed, d), 2) << seed;
    EXPECT_NE(drift_log(d).find("--seed"), std::string::npos) << drift_log(d);
  }
  EXPECT_EQ(run_drift(dunes + " --seed 18446744073709551615", d), 0) << drift_log(d);
  EXPECT_EQ(run_drift(dunes + " --seed 007", d), 0) << drift_log(d);
  fs::remove(out);
  const std::string scene = (d / "scene.toml").string();
  drift::testing::put(d / "scene.toml", "[terrain]\nraster = \"missing.tif\"\n");
  const std::string render = "render " + scene + " -o " + (d / "a.png").string();
  EXPECT_EQ(run_drift(render + " --spp 1e3", d), 2);
  EXPECT_NE(drift_log(d).find("whole number"), std::string::npos) << drift_log(d);
  EXPECT_EQ(run_drift("soil missing.toml -o " + (d / "s.ply").string() + " --steps 1e3", d), 2);
  EXPECT_NE(drift_log(d).find("whole number"), std::string::npos) << drift_log(d);
  EXPECT_EQ(run_drift(dunes + " --threads 2.5", d), 2);
  EXPECT_NE(drift_log(d).find("whole number"), std::string::npos) << drift_log(d);
  EXPECT_EQ(run_drift(render + " --size 100000x100000", d), 2);
  EXPECT_NE(drift_log(d).find("each side must be"), std::string::npos) << drift_log(d);
  EXPECT_EQ(run_drift(render + " --size 99999999999999999999x2", d), 2);
  EXPECT_NE(drift_log(d).find("each side must be"), std::string::npos) << drift_log(d);
  for (const char* tile : {"3/3", "0/0", "-1/3"}) {
    EXPECT_EQ(run_drift(render + " --tile " + tile, d), 2) << tile << ": " << drift_log(d);
  }
  EXPECT_FALSE(fs::exists(out) || fs::exists(d / "a.png"));
}
