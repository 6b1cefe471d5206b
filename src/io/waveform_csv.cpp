// Waveform CSV: "t_s,current_A" then numeric rows with strictly increasing time.
#include <fmt/format.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/io.hpp"

namespace gmasim {

namespace {

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

std::string read_file(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) {
    throw InputError(
        located(path, 0, fmt::format("cannot open waveform file ({})", std::strerror(errno))));
  }
  std::string text;
  char buf[1 << 14];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
  const bool failed = std::ferror(f) != 0;
  const int err = errno;
  std::fclose(f);
  if (failed) {
    throw InputError(
        located(path, 0, fmt::format("cannot read waveform file ({})", std::strerror(err))));
  }
  return text;
}

}  // namespace

Waveform load_waveform_csv(const std::string& path) {
  const std::string text = read_file(path);
  static constexpr std::string_view kColumns[2] = {"t_s", "current_A"};

  Waveform w;
  w.kind = WaveformKind::Table;
  w.table_source = path;

  std::string_view rest = text;
  if (rest.starts_with("\xEF\xBB\xBF")) rest.remove_prefix(3);  // UTF-8 byte-order mark
  long line_no = 0;
  bool header_seen = false;
  while (!rest.empty()) {
    const auto nl = rest.find('\n');
    const std::string_view raw = rest.substr(0, nl);
    rest = nl == std::string_view::npos ? std::string_view{} : rest.substr(nl + 1);
    ++line_no;
    const std::string_view line = trim(raw);
    if (line.empty()) continue;  // blank lines are skipped
    const auto cells = split_cells(line);
    if (!header_seen) {
      if (cells.size() != 2 || cells[0] != kColumns[0] || cells[1] != kColumns[1]) {
        throw InputError(located(path, line_no,
                                 fmt::format("expected header 't_s,current_A', "
                                             "got '{}'",
                                             line)));
      }
      header_seen = true;
      continue;
    }
    if (cells.size() != 2) {
      throw InputError(located(path, line_no,
                               fmt::format("expected 2 cells (t_s,current_A), "
                                           "got {}: '{}'",
                                           cells.size(), line)));
    }
    double v[2] = {0.0, 0.0};
    for (int c = 0; c < 2; ++c) {
      const std::string_view cell = cells[static_cast<std::size_t>(c)];
      if (cell.empty()) {
        throw InputError(
            located(path, line_no, fmt::format("empty cell in column {}", kColumns[c])));
      }
      // from_chars rejects a leading '+'; accept it as strtod would.
      const std::string_view digits = cell.starts_with('+') ? cell.substr(1) : cell;
      const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v[c]);
      if (ec != std::errc() || ptr != digits.data() + digits.size()) {
        const bool out_of_range = ec == std::errc::result_out_of_range;
        throw InputError(
            located(path, line_no,
                    fmt::format("{} cell '{}' in column {}",
                                out_of_range ? "out-of-range" : "non-numeric", cell, kColumns[c])));
      }
      if (std::isnan(v[c])) {
        throw InputError(
            located(path, line_no, fmt::format("NaN in column {} ('{}')", kColumns[c], cell)));
      }
      if (std::isinf(v[c])) {
        throw InputError(
            located(path, line_no, fmt::format("Inf in column {} ('{}')", kColumns[c], cell)));
      }
    }
    if (!w.table_t_s.empty() && !(v[0] > w.table_t_s.back())) {
      throw InputError(located(path, line_no,
                               fmt::format("time {:g} s does not increase (previous {:g} s)", v[0],
                                           w.table_t_s.back())));
    }
    w.table_t_s.push_back(v[0]);
    w.table_current_A.push_back(v[1]);
  }
  if (!header_seen) throw InputError(located(path, 1, "empty file"));
  if (w.table_t_s.size() < 2) {
    throw InputError(located(
        path, line_no, fmt::format("needs at least 2 data rows, found {}", w.table_t_s.size())));
  }
  return w;
}

}  // namespace gmasim
