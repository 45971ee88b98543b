// JSON text written by hand: a string as a string literal (quotes,
// backslashes and control characters escaped, RFC 8259, 7) and a number with
// the digits that read back as the same value. Shared by the Cryptomatte
// manifest, the frame's sidecar and the glTF writer.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

namespace drift::terrain {

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

// A number in %g form with `digits` significant digits: 17 read back as the
// same double, 9 as the same float.
inline std::string json_number(double v, int digits = 17) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

}  // namespace drift::terrain
