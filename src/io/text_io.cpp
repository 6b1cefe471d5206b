#include "io/text_io.hpp"

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
  const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (ec != std::errc() || ptr != digits.data() + digits.size())
    return ec == std::errc::result_out_of_range ? CellError::OutOfRange : CellError::NonNumeric;
  if (std::isnan(v)) return CellError::NaN;
  if (std::isinf(v)) return CellError::Inf;
  return CellError::None;
}

}  // namespace gmasim::io_detail
