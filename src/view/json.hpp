// JSON text for the view's messages (hello, status, errors): a string literal
// with its escapes and a number (null when not finite). Private to src/view.
#pragma once

#include <cmath>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace swirl::view::json {

// A JSON string literal (quotes, backslashes and control characters escaped).
inline std::string string(std::string_view s) {
  std::string out(1, '"');
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out.push_back('\\');
      out.push_back(c);
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out.append(fmt::format("\\u{:04x}", static_cast<unsigned char>(c)));
    } else {
      out.push_back(c);
    }
  }
  out.push_back('"');
  return out;
}

inline std::string number(double v) { return std::isfinite(v) ? fmt::format("{:.9g}", v) : std::string("null"); }

inline std::string boolean(bool b) { return b ? "true" : "false"; }

}  // namespace swirl::view::json
