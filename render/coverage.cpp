#include "render/coverage.h"

#include <algorithm>

#include "render/surface.h"
#include "terrain/error.h"

namespace drift::render {

CoverageChannels coverage_channels(const TerrainSurface& surface) {
  CoverageChannels c;
  auto channel = [&](const std::string& name) {
    const auto it = std::find(c.names.begin(), c.names.end(), name);
    if (it != c.names.end()) return static_cast<int>(it - c.names.begin());
    if (static_cast<int>(c.names.size()) == kMaxCoverage) {
      throw Error("the ground's materials have more than " + std::to_string(kMaxCoverage) +
                  " names (coverage channels); give rules and layers of one kind the same " +
                  "'name'");
    }
    c.names.push_back(name);
    return static_cast<int>(c.names.size()) - 1;
  };
  c.ground = channel(surface.ground_name);
  for (const MaterialRule& rule : surface.rules) c.rules.push_back(channel(rule.name));
  for (const MaterialLayer& layer : surface.layers) c.layers.push_back(channel(layer.name));
  for (const ObjectLayer& layer : surface.object_layers)
    c.object_layers.push_back(channel(layer.name));
  return c;
}

}  // namespace drift::render
