#include "common/text_io.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "gmasim/errors.hpp"
#include "gmasim/validate.hpp"

namespace gmasim::io_detail {

std::string read_text_file(const std::string& path, std::string_view what,
                           OnReadError on_read_error) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) {
    throw InputError(
        located(path, 0, fmt::format("cannot open {} ({})", what, std::strerror(errno))));
  }
  std::string text;
  char buf[1 << 14];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
    text.append(buf, n);
    if (text.size() > kMaxInputBytes) {  // /dev/zero, a runaway pipe, a wrong file
      std::fclose(f);
      throw InputError(located(path, 0,
                               fmt::format("{} is larger than {} MiB: not a gmasim input (limit "
                                           "kMaxInputBytes, docs/reliability.md)",
                                           what, kMaxInputBytes >> 20)));
    }
  }
  const bool failed = std::ferror(f) != 0;
  const int err = errno;
  std::fclose(f);
  if (failed && on_read_error == OnReadError::Throw) {
    throw InputError(
        located(path, 0, fmt::format("cannot read {} ({})", what, std::strerror(err))));
  }
  return text;
}

std::vector<std::string_view> split_lines(std::string_view text, StripCR strip_cr) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    auto end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    auto line = text.substr(start, end - start);
    if (strip_cr == StripCR::Yes && line.ends_with('\r')) line.remove_suffix(1);
    lines.push_back(line);
    start = end + 1;
  }
  return lines;
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string_view> split_cells(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    cells.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return cells;
}

CellError parse_finite(std::string_view cell, double& v) {
  if (cell.empty()) return CellError::Empty;
  const std::string_view digits = cell.starts_with('+') ? cell.substr(1) : cell;
  // One sign only: "+-1" is not a number (from_chars after the '+' would read -1).
  if (digits.size() != cell.size() && (digits.starts_with('-') || digits.starts_with('+')))
    return CellError::NonNumeric;
  const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (ec != std::errc() || ptr != digits.data() + digits.size())
    return ec == std::errc::result_out_of_range ? CellError::OutOfRange : CellError::NonNumeric;
  if (std::isnan(v)) return CellError::NaN;
  if (std::isinf(v)) return CellError::Inf;
  return CellError::None;
}

namespace {

bool is_bare_key_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

std::string shown(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x21 && u < 0x7f) return fmt::format("'{}'", c);
  return fmt::format("byte 0x{:02x}", static_cast<unsigned>(u));
}

}  // namespace

void guard_toml_text(std::string_view text, const std::string& source) {
  enum class Str { None, Basic, Literal, MlBasic, MlLiteral };
  Str str = Str::None;
  int depth = 0;  // [ and { nesting inside values
  long line = 1;
  bool line_start = true;
  auto fail = [&](const std::string& why) { throw InputError(located(source, line, why)); };
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);  // UTF-8 byte-order mark
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n; ++i) {
    const char c = text[i];
    if (c == '\0') fail("NUL byte: not a text file");
    if (c == '\n') {
      ++line;
      line_start = true;
      if (str == Str::Basic || str == Str::Literal) str = Str::None;  // toml++ reports it
      continue;
    }
    if (str == Str::Basic || str == Str::MlBasic) {
      if (c == '\\') {
        if (i + 1 < n && text[i + 1] != '\n') ++i;  // skip the escaped character
        continue;
      }
      if (c == '"') {
        if (str == Str::Basic)
          str = Str::None;
        else if (text.substr(i, 3) == "\"\"\"") {
          str = Str::None;
          i += 2;
        }
      }
      continue;
    }
    if (str == Str::Literal || str == Str::MlLiteral) {
      if (c == '\'') {
        if (str == Str::Literal)
          str = Str::None;
        else if (text.substr(i, 3) == "'''") {
          str = Str::None;
          i += 2;
        }
      }
      continue;
    }
    if (line_start && depth == 0) {
      if (c == ' ' || c == '\t' || c == '\r') continue;
      line_start = false;
      if (c == '[') {  // a table header: [key] or [[key]]
        std::size_t j = i + 1;
        if (j < n && text[j] == '[') ++j;
        while (j < n && (text[j] == ' ' || text[j] == '\t')) ++j;
        if (j >= n || !(is_bare_key_char(text[j]) || text[j] == '"' || text[j] == '\''))
          fail(fmt::format(
              "malformed table header: a key cannot start with {}",
              j >= n || text[j] == '\n' ? std::string("the end of the line") : shown(text[j])));
        // The rest of the header (quoted keys may hold brackets) is toml++'s to check.
        while (i + 1 < n && text[i + 1] != '\n') ++i;
        continue;
      }
      if (!(is_bare_key_char(c) || c == '"' || c == '\'' || c == '#'))
        fail(fmt::format("expected a key, a [table] or a comment; a key cannot start with {}",
                         shown(c)));
    }
    line_start = false;
    switch (c) {
      case '#':
        while (i + 1 < n && text[i + 1] != '\n') ++i;
        break;
      case '"':
        if (text.substr(i, 3) == "\"\"\"") {
          str = Str::MlBasic;
          i += 2;
        } else {
          str = Str::Basic;
        }
        break;
      case '\'':
        if (text.substr(i, 3) == "'''") {
          str = Str::MlLiteral;
          i += 2;
        } else {
          str = Str::Literal;
        }
        break;
      case '[':
      case '{':
        ++depth;
        break;
      case ']':
      case '}':
        if (depth > 0) --depth;
        break;
      default:
        break;
    }
  }
}

}  // namespace gmasim::io_detail
