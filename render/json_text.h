// A string as a JSON string literal: quotes, backslashes and control
// characters escaped (RFC 8259, 7). Shared by the Cryptomatte manifest and the
// frame's sidecar.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

namespace drift::render {

inline std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace drift::render
