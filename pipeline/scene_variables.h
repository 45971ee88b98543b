// Variables in scene files: `${NAME}` in any string of the file is replaced by
// NAME's value, so that a scene names the products it reads relative to a
// folder its caller chooses, as make's OUT does (`raster = "${OUT}/dunes.tif"`).
// The file's [variables] table gives defaults (`OUT = "../../out"`, so the scene
// renders on its own); `drift render --set NAME=VALUE` replaces them. A value
// becomes part of a path, which is then resolved as any path in the file is
// (relative ones against the scene file's folder).
#pragma once

#include <toml++/toml.h>

#include <filesystem>
#include <map>
#include <string>

namespace drift::pipeline {

using SceneVariables = std::map<std::string, std::string>;

// Whether `name` can name a variable: a letter or '_', then letters, digits, '_'.
bool is_variable_name(const std::string& name);

// Replaces every ${NAME} in the strings of `root` (tables and arrays, at any
// depth) by the value `overrides` or `root`'s [variables] table gives, in that
// order, and removes the [variables] table. Throws drift::Error naming the
// file, the line, the key and the variable for an unknown variable, a `${`
// without its `}`, or a [variables] entry that is not a string.
void expand_scene_variables(toml::table& root, const std::filesystem::path& file,
                            const SceneVariables& overrides);

}  // namespace drift::pipeline
