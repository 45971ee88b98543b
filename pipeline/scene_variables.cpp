#include "pipeline/scene_variables.h"

#include <cctype>
#include <string>

#include "terrain/error.h"

namespace drift::pipeline {

namespace {

struct Expansion {
  const SceneVariables& values;
  const std::filesystem::path& file;

  [[noreturn]] void fail(const toml::node& node, const std::string& key,
                         const std::string& problem) const {
    throw Error(file.string() + ":" + std::to_string(node.source().begin.line) + ": " + key + ": " +
                problem);
  }

  std::string expand(const std::string& text, const toml::node& node,
                     const std::string& key) const {
    std::string out;
    std::size_t at = 0;
    while (true) {
      const std::size_t open = text.find("${", at);
      if (open == std::string::npos) break;
      const std::size_t close = text.find('}', open + 2);
      if (close == std::string::npos)
        fail(node, key, "'${' without its closing '}' in \"" + text + "\"");
      const std::string name = text.substr(open + 2, close - open - 2);
      const auto value = values.find(name);
      if (!is_variable_name(name) || value == values.end())
        fail(node, key,
             std::string("unknown variable ${")
                 .append(name)
                 .append("}; define it in the file's [variables] table or give it with --set ")
                 .append(name)
                 .append("=VALUE"));
      out.append(text, at, open - at).append(value->second);
      at = close + 1;
    }
    return out.append(text, at);
  }

  void visit(toml::node& node, const std::string& key) const {
    if (toml::table* table = node.as_table()) {
      for (auto&& [k, child] : *table)
        visit(child, key.empty() ? std::string(k.str()) : key + "." + std::string(k.str()));
    } else if (toml::array* array = node.as_array()) {
      for (toml::node& child : *array) visit(child, key);
    } else if (toml::value<std::string>* string = node.as_string()) {
      string->get() = expand(string->get(), node, key);
    }
  }
};

}  // namespace

bool is_variable_name(const std::string& name) {
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) return false;
  for (const char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  return true;
}

void expand_scene_variables(toml::table& root, const std::filesystem::path& file,
                            const SceneVariables& overrides) {
  SceneVariables values;
  if (const toml::node* node = root.get("variables")) {
    const toml::table* table = node->as_table();
    if (!table)
      throw Error(file.string() + ":" + std::to_string(node->source().begin.line) +
                  ": [variables] must be a table of strings");
    for (const auto& [k, v] : *table) {
      const std::string name(k.str());
      if (!is_variable_name(name) || !v.is_string())
        throw Error(file.string() + ":" + std::to_string(v.source().begin.line) + ": [variables] " +
                    name + ": give a string, under a name of letters, digits and '_'");
      values[name] = *v.value<std::string>();
    }
    root.erase("variables");
  }
  for (const auto& [name, value] : overrides) values[name] = value;
  Expansion{values, file}.visit(root, "");
}

}  // namespace drift::pipeline
