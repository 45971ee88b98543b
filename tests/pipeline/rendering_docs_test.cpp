// docs/rendering.md's key table against the scene reader (issue 18, item 4):
// the reader (pipeline/scene_file.cpp) is the one source of every range and
// default; the docs must say the same. Every numeric key's range "lo - hi" is
// probed at both ends (accepted) and just beyond (refused), so a range changed
// on one side only fails here; the documented numeric defaults are compared
// with what the reader gives when the key is absent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "pipeline/scene_file.h"
#include "render/surface.h"
#include "terrain/error.h"
#include "terrain/raster_io.h"
#include "tests/markdown_table.h"

namespace fs = std::filesystem;
using drift::pipeline::SceneFile;

namespace {

// One key of a row of the table ("`[terrain] variation`, `bump`" is two keys).
struct DocumentedKey {
  std::string section, key, type, default_text, range_text;
};

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

std::vector<std::string> split(const std::string& s, const std::string& by) {
  std::vector<std::string> out;
  std::size_t from = 0;
  for (std::size_t at; (at = s.find(by, from)) != std::string::npos; from = at + by.size())
    out.push_back(trim(s.substr(from, at - from)));
  out.push_back(trim(s.substr(from)));
  return out;
}

// The rows of the table headed "| key | type | default | range | meaning |",
// one entry per key; where a row names several keys, a default or range list
// of the same length gives each its own, otherwise all share the cell.
std::vector<DocumentedKey> documented_keys() {
  std::vector<DocumentedKey> keys;
  const std::regex key_cell(R"(^`\[(\w+)\] (\w+)`(.*)$)");
  for (const auto& cells : drift::testing::markdown_table(
           DRIFT_SOURCE_DIR "/docs/rendering.md", "| key | type | default | range | meaning |")) {
    std::smatch m;
    if (cells.size() != 5 || !std::regex_match(cells[0], m, key_cell)) continue;
    std::vector<std::string> names = {m[2]};
    for (const std::string& more : split(m[3], ","))
      if (more.size() > 2) names.push_back(more.substr(1, more.size() - 2));
    const std::vector<std::string> defaults = split(cells[2], ", ");
    const std::vector<std::string> ranges = split(cells[3], ", ");
    for (std::size_t i = 0; i < names.size(); ++i) {
      keys.push_back({m[1], names[i], cells[1],
                      defaults.size() == names.size() ? defaults[i] : cells[2],
                      ranges.size() == names.size() ? ranges[i] : cells[3]});
    }
  }
  return keys;
}

// "0.01 - 100", "-20 - 20", "0 - 100000 m": the closed range; nullopt for
// anything else (lists of words, "odd, 1 - 9", units alone).
std::optional<std::pair<double, double>> closed_range(const std::string& text) {
  static const std::regex range(R"(^(-?[0-9.e+-]+) - (-?[0-9.e+-]+)( [a-z]+)?$)");
  std::smatch m;
  if (!std::regex_match(text, m, range)) return std::nullopt;
  return std::make_pair(std::stod(m[1]), std::stod(m[2]));
}

bool is_numeric_type(const std::string& type) {
  return type == "number" || type == "numbers" || type == "int" || type == "integer" ||
         type.find("or number") != std::string::npos;
}
bool is_integer_type(const std::string& type) { return type == "int" || type == "integer"; }

// What a key needs beside it to be read at all.
std::string companions(const DocumentedKey& k) {
  if (k.section == "ripples") return "raster = \"ripples.tif\"\n";
  if (k.section == "camera") return "from = [0, 0, 100]\nto = [1, 1, 0]\n";
  if (k.section == "terrain" && (k.key == "variation" || k.key == "bump" || k.key == "bump_scale"))
    return "material = \"rock\"\n";
  return "";
}

std::string scene_with(const DocumentedKey& k, const std::string& value) {
  std::string terrain = "[terrain]\nraster = \"dem.tif\"\n";
  const std::string line = k.key + " = " + value + "\n" + companions(k);
  if (k.section == "terrain") return terrain + line;
  return terrain + "[" + k.section + "]\n" + line;
}

std::string format(double v, bool integer) {
  char buf[64];
  if (integer) {
    std::snprintf(buf, sizeof buf, "%.0f", v);
  } else {
    std::snprintf(buf, sizeof buf, "%.17g", v);
    if (std::string(buf).find_first_of(".e") == std::string::npos) std::strcat(buf, ".0");
  }
  return buf;
}

fs::path scene_dir() {
  static const fs::path dir = [] {
    std::string pattern = (fs::temp_directory_path() / "drift_rendering_docs_XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    return fs::path(pattern);
  }();
  return dir;
}

// The reader's error for `text`, or "" when it reads.
std::string error_of(const std::string& text) {
  const fs::path p = scene_dir() / "s.toml";
  std::ofstream(p) << text;
  try {
    drift::pipeline::read_scene_file(p);
  } catch (const drift::Error& e) {
    return e.what();
  }
  return "";
}

SceneFile read(const std::string& text) {
  const fs::path p = scene_dir() / "s.toml";
  std::ofstream(p) << text;
  return drift::pipeline::read_scene_file(p);
}

// The snow as the scene's loaders lay it, given a cover and a depth raster:
// the layer that holds the [snow] keys' values.
drift::render::MaterialLayer loaded_snow(SceneFile s) {
  const drift::terrain::HeightField tiny(2, 2, 0.5f, drift::terrain::local_georeference(1.0));
  drift::terrain::write_geotiff(tiny, scene_dir() / "snow.tif");
  s.product_files["snow.cover"] = s.product_files["snow.depth"] = scene_dir() / "snow.tif";
  for (const auto& [section, load] : s.product_loaders) load(s);
  return s.input.surface.layers.back();
}

// The snow material objects take ([snow]'s look).
const drift::render::Material& object_snow(const SceneFile& s) {
  return s.input.surface.object_layers.at(0).material;
}

// The value the reader leaves for a key the scene does not give.
using Getter = std::function<double(const SceneFile&)>;
const std::map<std::string, Getter>& getters() {
  static const std::map<std::string, Getter> table = {
      {"terrain.exaggeration", [](const SceneFile& s) { return s.input.vertical_exaggeration; }},
      {"terrain.repeat", [](const SceneFile& s) { return s.terrain_repeat; }},
      {"terrain.roughness", [](const SceneFile& s) { return s.input.surface.ground.roughness; }},
      {"terrain.wetness", [](const SceneFile& s) { return s.input.surface.ground.wetness; }},
      {"terrain.surround_reach", [](const SceneFile& s) { return s.input.surround.reach; }},
      {"terrain.position_radius", [](const SceneFile& s) { return s.position_radius; }},
      {"snow.roughness", [](const SceneFile& s) { return object_snow(s).roughness; }},
      {"snow.cover_outside", [](const SceneFile& s) { return loaded_snow(s).outside; }},
      {"snow.forward_scattering",
       [](const SceneFile& s) { return object_snow(s).forward_scattering; }},
      {"snow.scattering", [](const SceneFile& s) { return loaded_snow(s).thickness->scattering; }},
      {"sun.azimuth", [](const SceneFile& s) { return s.input.sun.azimuth_deg; }},
      {"sun.elevation", [](const SceneFile& s) { return s.input.sun.elevation_deg; }},
      {"sun.angular_diameter", [](const SceneFile& s) { return s.input.sun.angular_diameter_deg; }},
      {"sun.irradiance", [](const SceneFile& s) { return s.input.sun.irradiance; }},
      {"sky.haze", [](const SceneFile& s) { return s.input.sky.haze; }},
      {"sky.shaft_steps", [](const SceneFile& s) { return s.input.sky.shaft_steps; }},
      {"sky.intensity", [](const SceneFile& s) { return s.input.sky.intensity; }},
      {"sky.ground_factor", [](const SceneFile& s) { return s.input.sky.ground_factor; }},
      {"render.width", [](const SceneFile& s) { return s.settings.width; }},
      {"render.height", [](const SceneFile& s) { return s.settings.height; }},
      {"render.spp", [](const SceneFile& s) { return s.settings.samples_per_pixel; }},
      {"render.max_depth", [](const SceneFile& s) { return s.settings.max_depth; }},
      {"render.noise_target", [](const SceneFile& s) { return s.settings.noise_target; }},
      {"render.min_spp", [](const SceneFile& s) { return s.settings.min_samples; }},
      {"render.seed", [](const SceneFile& s) { return static_cast<double>(s.settings.seed); }},
      {"output.exposure_compensation",
       [](const SceneFile& s) { return s.display.exposure_ev; }},  // auto: the compensation
  };
  return table;
}

// A plain number as the default cell gives it ("0 (off)" is 0).
std::optional<double> documented_number(const std::string& text) {
  static const std::regex number(R"(^(-?[0-9.]+)( \(.*\))?$)");
  std::smatch m;
  if (!std::regex_match(text, m, number)) return std::nullopt;
  return std::stod(m[1]);
}

}  // namespace

TEST(RenderingDocs, TheTableIsReadAndCoversTheNumericKeys) {
  const auto keys = documented_keys();
  ASSERT_GT(keys.size(), 50u) << "docs/rendering.md's key table was not found";
  int ranged = 0;
  for (const DocumentedKey& k : keys)
    ranged += is_numeric_type(k.type) && closed_range(k.range_text);
  EXPECT_GE(ranged, 30) << "fewer numeric keys with a range than expected";
}

TEST(RenderingDocs, EveryDocumentedRangeIsTheReadersRange) {
  for (const DocumentedKey& k : documented_keys()) {
    if (!is_numeric_type(k.type)) continue;
    const auto range = closed_range(k.range_text);
    if (!range) continue;
    const bool integer = is_integer_type(k.type);
    const auto [lo, hi] = *range;
    const double beyond = integer ? 1.0 : std::max(1e-9, 1e-6 * (hi - lo));
    const std::string name = "[" + k.section + "] " + k.key;
    EXPECT_EQ(error_of(scene_with(k, format(lo, integer))), "") << name << " = " << lo;
    EXPECT_EQ(error_of(scene_with(k, format(hi, integer))), "") << name << " = " << hi;
    EXPECT_NE(error_of(scene_with(k, format(lo - beyond, integer))), "")
        << name << " takes " << lo - beyond << ", below the documented " << k.range_text;
    EXPECT_NE(error_of(scene_with(k, format(hi + beyond, integer))), "")
        << name << " takes " << hi + beyond << ", above the documented " << k.range_text;
  }
}

TEST(RenderingDocs, EveryNumericKeyDocumentsAClosedRange) {
  // "Every number is checked": a range the reader enforces is a range the
  // docs state, both ends, so that the probe above can hold it.
  for (const DocumentedKey& k : documented_keys()) {
    if (!is_numeric_type(k.type) || k.range_text.empty()) continue;
    if (k.range_text.rfind(">", 0) == 0)
      ADD_FAILURE() << "[" << k.section << "] " << k.key << ": '" << k.range_text
                    << "' leaves the reader's upper bound undocumented";
  }
}

TEST(RenderingDocs, DocumentedDefaultsAreTheReadersDefaults) {
  const SceneFile plain = read("[terrain]\nraster = \"dem.tif\"\n");
  int checked = 0;
  for (const DocumentedKey& k : documented_keys()) {
    const auto getter = getters().find(k.section + "." + k.key);
    const auto value = documented_number(k.default_text);
    if (getter == getters().end() || !value) continue;
    EXPECT_NEAR(getter->second(plain), *value, 1e-6 * std::max(1.0, std::fabs(*value)))
        << "[" << k.section << "] " << k.key << ": docs/rendering.md says " << k.default_text;
    ++checked;
  }
  EXPECT_GE(checked, 20) << "the docs' defaults were not found";
}
