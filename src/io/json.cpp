#include "io/json.hpp"

#include <fmt/format.h>

#include <cmath>

namespace gmasim::io_detail {

std::string json_string(std::string_view s, BackspaceFormFeed bf) {
  const bool short_bf = bf == BackspaceFormFeed::Short;
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (short_bf && c == '\b') {
          out += "\\b";
        } else if (short_bf && c == '\f') {
          out += "\\f";
        } else if (c < 0x20 || c == 0x7f) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
        } else {
          out += ch;  // UTF-8 passes through unchanged
        }
    }
  }
  out += '"';
  return out;
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  return fmt::format("{}", v);
}

}  // namespace gmasim::io_detail
