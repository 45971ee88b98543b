// One validation idiom (issue 18): library code checks its options struct in
// validate() and speaks of fields; the command line maps the field to its flag.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "snow/snow_cover.h"
#include "snow/snowfall.h"
#include "terrain/import.h"
#include "terrain/parameter.h"

namespace fs = std::filesystem;

namespace {

// Runs `drift ARGS`; returns the exit status and fills `err` with stderr.
int run_drift(const std::string& args, std::string& err) {
  const fs::path log =
      fs::temp_directory_path() /
      ("drift_option_errors_" +
       std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + ".log");
  const std::string cmd = std::string(DRIFT_EXECUTABLE) + " " + args + " 2> " + log.string();
  const int status = std::system(cmd.c_str());
  std::ifstream f(log);
  std::stringstream s;
  s << f.rdbuf();
  err = s.str();
  fs::remove(log);
  return WEXITSTATUS(status);
}

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
  const std::string out = (fs::temp_directory_path() / "drift_option_errors.tif").string();
  std::string err;
  EXPECT_EQ(run_drift("snow cover missing.tif -o " + out + " --region 40", err), 2);
  EXPECT_NE(err.find("--region is 40; it must lie in (0, 32]"), std::string::npos) << err;
  EXPECT_EQ(run_drift("snow fall missing.tif -o " + out + " --spread 40", err), 2);
  EXPECT_NE(err.find("--spread is 40"), std::string::npos) << err;
  EXPECT_EQ(run_drift("import missing.tif -o " + out + " --exaggerate 0", err), 1);
  EXPECT_NE(err.find("--exaggerate is 0"), std::string::npos) << err;
  EXPECT_EQ(run_drift("dunes --size 32 --L0 100 -o " + out, err), 1);
  EXPECT_NE(err.find("--L0 is 100"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(out));
}
