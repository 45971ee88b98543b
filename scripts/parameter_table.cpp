// The parameter tables' generator (scripts/parameter_table.cmake runs it at
// build time): reads a stage's NAME_parameters.toml with toml++ and writes the
// C++ definition of `NAME_parameters()`, a terrain::Parameter table whose rows
// are bound to the options struct's fields by their own `field` (a misspelt
// field does not compile). Strict: a key it does not know, a value of the
// wrong type or form, or a missing one stops the build with
// "FILE:LINE: KEY: what is wrong", exit 1. The table's form:
//
//   header = "terrain/soil/soil_parameters.h"   # declares NAME_parameters()
//   namespace = "drift::soil"
//   options = "SoilOptions"                      # the struct the rows set
//   [[parameter]]
//   field = "soil.phi_deg"     # the struct's member, as errors name it
//   flag = "--phi"             # optional: the command line's flag
//   range = "[0, 60)"          # [ or ( then lo, hi (a number or inf), ] or )
//   integer = true             # optional: a whole number
//   unit = "degrees"           # optional
//   meaning = "angle of internal friction phi"
//   key = "[soil] phi"         # optional: the key in a scene or scenario file
//
//   parameter_table IN.toml OUT.cpp
// OUT is written whole or not at all (through OUT.part).
#include <toml++/toml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <string_view>

#include "terrain/json_text.h"

namespace {

struct TableError {
  toml::source_position where;
  std::string key, what;
};

[[noreturn]] void fail(const toml::node& at, const std::string& key, const std::string& what) {
  throw TableError{at.source().begin, key, what};
}

// A string as a C++ literal: JSON's escapes (quotes, backslashes, newlines)
// are C++'s for every string text_of() lets through.
std::string literal(std::string_view text) { return drift::terrain::json_string(text); }

// The string at `key` of `table`: "" if it is absent and not `required`.
std::string text_of(const toml::table& table, const std::string& key, bool required,
                    const std::string& row) {
  const toml::node* node = table.get(key);
  if (!node) {
    if (required) fail(table, key, row + " has no " + key + " (write " + key + " = \"...\")");
    return "";
  }
  const auto* s = node->as_string();
  if (!s) fail(*node, key, "must be a string in quotes");
  for (const char c : s->get())
    if (static_cast<unsigned char>(c) < 0x20 && c != '\n')
      fail(*node, key, "holds a control character (a tab?): write plain text");
  return s->get();
}

// Refuses any key of `table` that `known` (space-separated, between spaces) lacks.
void only_keys(const toml::table& table, const std::string& known) {
  for (const auto& [key, node] : table) {
    std::string word(1, ' ');  // append, not " " + ...: GCC 12 warns falsely (-Wrestrict)
    word.append(key.str()).append(1, ' ');
    if (known.find(word) == std::string::npos)
      fail(node, std::string(key.str()),
           "unknown key (the keys:" + known.substr(0, known.size() - 1) + ")");
  }
}

// One row of the table as the C++ initialiser the old reader wrote.
std::string row_of(const toml::table& row, const std::string& options) {
  only_keys(row, " field flag range integer unit meaning key ");
  const std::string field = text_of(row, "field", true, "a row");
  const std::string named = "the row of field " + literal(field);
  if (!std::regex_match(field, std::regex("[A-Za-z_][A-Za-z0-9_]*(\\.[A-Za-z_][A-Za-z0-9_]*)*")))
    fail(*row.get("field"), "field", "'" + field + "' is not a member name (a.b_c)");
  const std::string range = text_of(row, "range", true, named);
  const std::string meaning = text_of(row, "meaning", true, named);
  // "[lo, hi]" with ( or ) for an open end; lo and hi plain numbers, hi inf.
  const std::string number = "[-+]?[0-9][0-9.eE+-]*";
  std::smatch m;
  if (!std::regex_match(range, m,
                        std::regex("([\\[\\(])(" + number + "), (" + number + "|inf)([\\]\\)])")))
    fail(*row.get("range"), "range",
         "'" + range + "' is not \"[lo, hi]\" (( or ) for an open end; hi may be inf)");
  const std::string lo = m[2], hi = m[3];
  char* end = nullptr;
  const double lo_value = std::strtod(lo.c_str(), &end);
  if (*end) fail(*row.get("range"), "range", "'" + lo + "' is not a number");
  const double hi_value = hi == "inf" ? HUGE_VAL : std::strtod(hi.c_str(), &end);
  if (hi != "inf" && *end) fail(*row.get("range"), "range", "'" + hi + "' is not a number");
  if (!(lo_value <= hi_value)) fail(*row.get("range"), "range", "'" + range + "' is empty");
  const bool open_low = m[1] == "(", open_high = m[4] == ")";
  const char* ends = open_low && open_high ? "Open"
                     : open_low            ? "OpenLow"
                     : open_high           ? "OpenHigh"
                                           : "Closed";
  bool integer = false;
  if (const toml::node* node = row.get("integer")) {
    const auto* b = node->as_boolean();
    if (!b) fail(*node, "integer", "must be true or false");
    integer = b->get();
  }
  return "    {" + literal(field) + ", " + literal(text_of(row, "flag", false, named)) + ", " + lo +
         ", " + hi + ", Ends::" + ends + ", " + (integer ? "true" : "false") + ", " +
         literal(text_of(row, "unit", false, named)) + ", " + literal(meaning) +
         ", DRIFT_PARAMETER_FIELD(" + options + ", " + field + "), " +
         literal(text_of(row, "key", false, named)) + "},\n";
}

// A subcommand's flags as data (pipeline/cmd_NAME_flags.toml): `function`
// (the flags function's name), `options` (its struct), then one [[flag]] a
// flag in --help order, written as the statement that declares it:
//   name = "--spp"  field = "spp"  help = "..."   sub->add_option(name, o->field, help)
//   switch = true                                  add_flag instead (a bool)
//   required = true                                ->required()
//   one_value = true                               ->allow_extra_args(false)
//   whole = ["1", "kMax"]                          whole_in_range(option, lo, hi)
//   range = ["0.0", "1.0"]                         ->check(CLI::Range(lo, hi))
//   member_of = "{16, 32}"                         ->check(CLI::IsMember({16, 32}))
// or a row of code alone, call = "add_seed_option(*sub, o->seed)".
// The bounds and calls are C++ as written; the strings become literals.
std::string flag_of(const toml::table& row) {
  only_keys(row, " name field help switch required one_value whole range member_of call ");
  auto flag = [&](const char* key) {
    const toml::node* node = row.get(key);
    if (node && !node->is_boolean()) fail(*node, key, "must be true or false");
    return node && node->as_boolean()->get();
  };
  auto pair = [&](const char* key) {
    const toml::node* node = row.get(key);
    const toml::array* a = node ? node->as_array() : nullptr;
    if (node && (!a || a->size() != 2 || !a->is_homogeneous(toml::node_type::string)))
      fail(*node, key, "must be two bounds, [\"lo\", \"hi\"] (C++ expressions)");
    return a ? (*a)[0].as_string()->get() + ", " + (*a)[1].as_string()->get() : std::string();
  };
  if (row.get("call")) {
    if (row.size() != 1) fail(row, "call", "a call row holds the call alone");
    return "  " + text_of(row, "call", true, "a call row") + ";\n";
  }
  const std::string name = text_of(row, "name", true, "a flag");
  const std::string named = "the flag " + name;
  std::string statement = "sub->" + std::string(flag("switch") ? "add_flag" : "add_option") + "(" +
                          literal(name) + ", o->" + text_of(row, "field", true, named) + ", " +
                          literal(text_of(row, "help", true, named)) + ")";
  if (flag("required")) statement += "->required()";
  if (flag("one_value")) statement += "->allow_extra_args(false)";
  if (const std::string bounds = pair("whole"); !bounds.empty())
    statement = "whole_in_range(" + statement + ", " + bounds + ")";
  if (const std::string bounds = pair("range"); !bounds.empty())
    statement += "->check(CLI::Range(" + bounds + "))";
  if (const std::string set = text_of(row, "member_of", false, named); !set.empty())
    statement += "->check(CLI::IsMember(" + set + "))";
  return "  " + statement + ";\n";
}

std::string flags_source_of(const toml::table& top, const std::filesystem::path& toml_path) {
  only_keys(top, " function options flag ");
  const std::string function = text_of(top, "function", true, "the flag list");
  const std::string options = text_of(top, "options", true, "the flag list");
  const toml::node* node = top.get("flag");
  const toml::array* rows = node ? node->as_array() : nullptr;
  if (!rows || !rows->is_array_of_tables())
    fail(node ? *node : top, "flag", "must be rows written [[flag]]");
  std::string body;
  for (const toml::node& row : *rows) body += flag_of(*row.as_table());
  return "// Generated from " + toml_path.filename().string() +
         " by scripts/parameter_table.cmake: edit that file.\n" + "void " + function +
         "(CLI::App* sub, " + options + "* o) {\n" + body + "}\n";
}

std::string source_of(const toml::table& top, const std::filesystem::path& toml_path) {
  if (top.get("function")) return flags_source_of(top, toml_path);
  only_keys(top, " header namespace options parameter ");
  const std::string header = text_of(top, "header", true, "the table");
  const std::string space = text_of(top, "namespace", true, "the table");
  const std::string options = text_of(top, "options", true, "the table");
  std::string rows;
  if (const toml::node* node = top.get("parameter")) {
    const auto* array = node->as_array();
    if (!array || !array->is_array_of_tables())
      fail(*node, "parameter", "must be rows written [[parameter]]");
    for (const toml::node& row : *array) rows += row_of(*row.as_table(), options);
  }
  const std::string name = toml_path.stem().string();
  return "// Generated from " + toml_path.filename().string() +
         " by scripts/parameter_table.cmake: edit that file.\n" + "#include \"" + header +
         "\"\n\n#include <limits>\n\nnamespace " + space + " {\n\n" +
         "const std::vector<terrain::Parameter<" + options + ">>& " + name + "() {\n" +
         "  using terrain::Ends;\n" +
         "  [[maybe_unused]] constexpr double inf = std::numeric_limits<double>::infinity();\n" +
         "  static const std::vector<terrain::Parameter<" + options + ">> table = {\n" + rows +
         "  };\n  return table;\n}\n\n}  // namespace " + space + "\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: parameter_table IN.toml OUT.cpp\n");
    return 2;
  }
  const std::filesystem::path in = argv[1], out = argv[2];
  std::string source;
  try {
    source = source_of(toml::parse_file(in.string()), in);
  } catch (const toml::parse_error& e) {
    std::fprintf(stderr, "%s:%u: not TOML: %.*s\n", in.c_str(), e.source().begin.line,
                 static_cast<int>(e.description().size()), e.description().data());
    return 1;
  } catch (const TableError& e) {
    std::fprintf(stderr, "%s:%u: %s: %s\n", in.c_str(), e.where.line, e.key.c_str(),
                 e.what.c_str());
    return 1;
  }
  const std::filesystem::path part = out.string() + ".part";
  if (!(std::ofstream(part, std::ios::binary) << source)) {
    std::fprintf(stderr, "%s: cannot write it\n", part.c_str());
    return 1;
  }
  std::filesystem::rename(part, out);
  return 0;
}
