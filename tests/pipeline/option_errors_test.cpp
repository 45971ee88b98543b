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
  EXPECT_EQ(run_drift("dunes --size 32 --L0 100 -o " + out, d), 1);
  EXPECT_NE(drift_log(d).find("--L0 is 100"), std::string::npos) << drift_log(d);
  EXPECT_FALSE(fs::exists(out));
}
