// Strict reading of one TOML table for the pipeline's files (scene files,
// object lists): typed getters with ranges, and finish() reporting any key
// that was not asked for (like pbrt's ReportUnused).
#pragma once

#include <toml++/toml.h>

#include <Eigen/Core>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "terrain/error.h"
#include "terrain/input_path.h"
#include "terrain/parameter.h"

namespace drift::pipeline {

// Parses a TOML file; a missing file or a syntax error is a drift::Error
// naming `what`, the file and the line.
inline toml::table parse_toml_file(const std::filesystem::path& path, const char* what) {
  check_input_file(path, what);
  try {
    return toml::parse_file(path.string());
  } catch (const toml::parse_error& e) {
    throw Error(path.string() + ":" + std::to_string(e.source().begin.line) +
                ": TOML syntax error: " + std::string(e.description()));
  }
}

// Reads one table's keys, remembering which were used, so that anything left
// over is reported as unknown (like pbrt's ReportUnused). Every error names
// the file and the line of the key (or of the table).
class Section {
 public:
  // `doc`: the page that lists the table's keys, named by finish().
  Section(const toml::table* table, std::string name, const std::filesystem::path& file,
          std::string doc = "docs/rendering.md")
      : table_(table), name_(std::move(name)), file_(file), doc_(std::move(doc)) {}

  // Whether the file has the table at all.
  bool present() const { return table_ != nullptr; }
  // Whether the table gives `key` (without taking it).
  bool has(const char* key) const { return table_ && table_->contains(key); }

  double number(const char* key, double fallback, double lo, double hi) {
    const toml::node* node = take(key);
    if (!node) return fallback;
    std::optional<double> v = node->value<double>();
    if (!v || node->is_boolean()) fail(key, *node, "must be a number");
    if (!std::isfinite(*v) || *v < lo || *v > hi) {
      fail(key, *node,
           "is " + terrain::refused_value(*v) + "; it must lie in [" + fmt(lo) + ", " + fmt(hi) +
               "]");
    }
    return *v;
  }
  int integer(const char* key, int fallback, long lo, long hi) {
    const toml::node* node = take(key);
    if (!node) return fallback;
    std::optional<std::int64_t> v = node->as_integer() ? node->value<std::int64_t>() : std::nullopt;
    if (!v) fail(key, *node, "must be an integer");
    if (*v < lo || *v > hi) {
      fail(key, *node,
           "is " + std::to_string(*v) + "; it must lie in [" + std::to_string(lo) + ", " +
               std::to_string(hi) + "]");
    }
    return static_cast<int>(*v);
  }
  // A 64-bit seed, the range of the command line's --seed: an integer >= 0,
  // or a string of decimal digits for seeds above 2^63 - 1 (TOML's integers
  // are signed 64-bit).
  std::uint64_t seed(const char* key, std::uint64_t fallback) {
    const toml::node* node = take(key);
    if (!node) return fallback;
    const char* range = "must be a whole number in [0, 18446744073709551615] (a string above 2^63)";
    if (const auto v = node->as_integer() ? node->value<std::int64_t>() : std::nullopt) {
      if (*v < 0) fail(key, *node, "is " + std::to_string(*v) + "; it " + range);
      return static_cast<std::uint64_t>(*v);
    }
    const auto text = node->value<std::string>();
    if (!node->is_string() || text->empty() || text->size() > 20 ||
        text->find_first_not_of("0123456789") != std::string::npos)
      fail(key, *node, range);
    errno = 0;
    const unsigned long long v = std::strtoull(text->c_str(), nullptr, 10);
    if (errno == ERANGE) fail(key, *node, "is " + *text + "; it " + range);
    return v;
  }
  bool boolean(const char* key, bool fallback) {
    const toml::node* node = take(key);
    if (!node) return fallback;
    if (!node->is_boolean()) fail(key, *node, "must be true or false");
    return *node->value<bool>();
  }
  std::optional<std::string> string(const char* key) {
    const toml::node* node = take(key);
    if (!node) return std::nullopt;
    if (!node->is_string()) fail(key, *node, "must be a string");
    return *node->value<std::string>();
  }
  std::vector<std::string> strings(const char* key) {
    const toml::node* node = take(key);
    if (!node) return {};
    if (node->is_string()) return {*node->value<std::string>()};
    const toml::array* a = node->as_array();
    std::vector<std::string> out;
    if (!a) fail(key, *node, "must be a string or an array of strings");
    for (const toml::node& e : *a) {
      if (!e.is_string()) fail(key, *node, "must be a string or an array of strings");
      out.push_back(*e.value<std::string>());
    }
    return out;
  }
  // An array of exactly N numbers, each in [lo, hi].
  template <int N>
  std::optional<Eigen::Matrix<double, N, 1>> vector(const char* key, double lo, double hi) {
    const toml::node* node = take(key);
    if (!node) return std::nullopt;
    const toml::array* a = node->as_array();
    if (!a || a->size() != N) {
      fail(key, *node, "must be an array of " + std::to_string(N) + " numbers");
    }
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) {
      const toml::node& e = *a->get(static_cast<std::size_t>(i));
      std::optional<double> d = e.value<double>();
      if (!d || e.is_boolean() || !std::isfinite(*d) || *d < lo || *d > hi) {
        fail(key, *node,
             "must hold " + std::to_string(N) + " finite numbers in [" + fmt(lo) + ", " + fmt(hi) +
                 "]");
      }
      v[i] = *d;
    }
    return v;
  }
  Eigen::Vector3f color(const char* key, const Eigen::Vector3f& fallback) {
    auto v = vector<3>(key, 0.0, 1.0);
    return v ? v->cast<float>() : fallback;
  }

  // The key's node as it is (null if absent), for values of more than one type.
  const toml::node* raw(const char* key) { return take(key); }

  // An array of tables ([[name.key]] entries), empty if absent.
  std::vector<const toml::table*> tables(const char* key) {
    const toml::node* node = take(key);
    if (!node) return {};
    const toml::array* a = node->as_array();
    std::vector<const toml::table*> out;
    if (a) {
      for (const toml::node& e : *a) out.push_back(e.as_table());
    }
    if (!a || std::find(out.begin(), out.end(), nullptr) != out.end()) {
      fail(key, *node, "must be an array of tables ([[" + name_ + "." + key + "]])");
    }
    return out;
  }

  // Reads the keys of a parameter table (terrain/parameter.h) that belong to
  // this table (a row's key "[name] key") into `o`, where given: numbers,
  // whole for integer rows, in each row's range.
  template <class Options>
  void parameters(const std::vector<terrain::Parameter<Options>>& table, Options& o) {
    const std::string prefix = "[" + name_ + "] ";
    for (const terrain::Parameter<Options>& p : table) {
      const std::string key(p.key);
      if (key.rfind(prefix, 0) == 0) parameter(p, key.substr(prefix.size()), o);
    }
  }

  // Reports a bad value of `key` (read before) with the file and line.
  [[noreturn]] void invalid(const char* key, const std::string& what) const {
    const toml::node* node = table_ ? table_->get(key) : nullptr;
    if (node) fail(key, *node, what);
    throw Error(file_.string() + ": '" + name_ + "." + key + "' " + what);
  }
  // Reports a problem with the table as a whole.
  [[noreturn]] void invalid_table(const std::string& what) const {
    std::string s = file_.string();
    if (table_ && table_->source().begin.line > 0)
      s += ":" + std::to_string(table_->source().begin.line);
    throw Error(s + ": [" + name_ + "] " + what);
  }

  // Call last: any key not taken is unknown.
  void finish() const {
    if (!table_) return;
    for (const auto& [k, node] : *table_) {
      if (!used_.count(std::string(k.str()))) {
        throw Error(where(node) + ": unknown key '" + name_ + "." + std::string(k.str()) +
                    "' (see " + doc_ + " for the keys of [" + name_ + "])");
      }
    }
  }

 private:
  template <class Options>
  void parameter(const terrain::Parameter<Options>& p, const std::string& key, Options& o) {
    const toml::node* node = take(key.c_str());
    if (!node) return;
    const std::optional<double> v = node->value<double>();
    if (!v || node->is_boolean()) fail(key.c_str(), *node, "must be a number");
    if (p.integer && !node->is_integer()) fail(key.c_str(), *node, "must be an integer");
    if (!p.admits(*v))
      fail(key.c_str(), *node,
           "is " + terrain::refused_value(*v) + "; it must lie in " + p.range());
    p.set(o, *v);
  }
  const toml::node* take(const char* key) {
    used_.insert(key);
    return table_ ? table_->get(key) : nullptr;
  }
  std::string where(const toml::node& node) const {
    std::string s = file_.string();
    if (node.source().begin.line > 0) s += ":" + std::to_string(node.source().begin.line);
    return s;
  }
  [[noreturn]] void fail(const char* key, const toml::node& node, const std::string& what) const {
    throw Error(where(node) + ": '" + name_ + "." + key + "' " + what);
  }
  static std::string fmt(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }

  const toml::table* table_;
  std::string name_;
  std::filesystem::path file_;
  std::string doc_;
  std::set<std::string> used_;
};

}  // namespace drift::pipeline
