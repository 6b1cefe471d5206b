// Waveform CSV: "t_s,current_A" then numeric rows with strictly increasing time.
#include <fmt/format.h>

#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "common/text_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

namespace {

// A parsed row (v: t_s, current_A) appended to the table, after the rules that need the line:
// the current within the coil limit (issue 19, item 11: with file:line and the value as
// written), time increasing.
void append_row(const std::string& path, long line_no, std::string_view current_cell,
                const double (&v)[2], Waveform& w) {
  if (!(std::fabs(v[1]) <= kMaxCurrent_A))
    throw InputError(
        located(path, line_no,
                fmt::format("current_A = {} A: must be in [{:g}, {:g}] A (the coil current limit)",
                            current_cell, -kMaxCurrent_A, kMaxCurrent_A)));
  if (!w.table_t_s.empty() && !(v[0] > w.table_t_s.back()))
    throw InputError(located(
        path, line_no,
        fmt::format("time {:g} s does not increase (previous {:g} s)", v[0], w.table_t_s.back())));
  w.table_t_s.push_back(v[0]);
  w.table_current_A.push_back(v[1]);
}

// A comment line before the header: "# period_s = P" declares the waveform's period (the
// metrics are over the run's last P seconds); other comments are notes, skipped.
void read_comment(const std::string& path, long line_no, std::string_view line, Waveform& w) {
  std::string_view body = io_detail::trim(line.substr(1));
  const auto eq = body.find('=');
  if (eq == std::string_view::npos || io_detail::trim(body.substr(0, eq)) != "period_s") return;
  const std::string_view value = io_detail::trim(body.substr(eq + 1));
  double P = 0.0;
  if (io_detail::parse_finite(value, P) != io_detail::CellError::None || !(P > 0.0))
    throw InputError(located(
        path, line_no,
        fmt::format("period_s = '{}': the waveform's period must be a number > 0 s", value)));
  w.table_period_s = P;
}

}  // namespace

Waveform load_waveform_csv(const std::string& path) {
  const std::string text = io_detail::read_text_file(path, "waveform file");
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
    const std::string_view line = io_detail::trim(raw);
    if (line.empty()) continue;                   // blank lines are skipped
    if (!header_seen && line.starts_with('#')) {  // comments before the header
      read_comment(path, line_no, line, w);
      continue;
    }
    const auto cells = io_detail::split_cells(line);
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
      using io_detail::CellError;
      const CellError err = io_detail::parse_finite(cell, v[c]);
      switch (err) {
        case CellError::None:
          break;
        case CellError::Empty:
          throw InputError(
              located(path, line_no, fmt::format("empty cell in column {}", kColumns[c])));
        case CellError::NonNumeric:
        case CellError::OutOfRange:
          throw InputError(
              located(path, line_no,
                      fmt::format("{} cell '{}' in column {}",
                                  err == CellError::OutOfRange ? "out-of-range" : "non-numeric",
                                  cell, kColumns[c])));
        case CellError::NaN:
          throw InputError(
              located(path, line_no, fmt::format("NaN in column {} ('{}')", kColumns[c], cell)));
        case CellError::Inf:
          throw InputError(
              located(path, line_no, fmt::format("Inf in column {} ('{}')", kColumns[c], cell)));
      }
    }
    append_row(path, line_no, cells[1], v, w);
  }
  if (!header_seen) throw InputError(located(path, 1, "empty file"));
  if (w.table_t_s.size() < 2) {
    throw InputError(located(
        path, line_no, fmt::format("needs at least 2 data rows, found {}", w.table_t_s.size())));
  }
  if (w.table_period_s > w.table_t_s.back())
    throw InputError(located(path, 1,
                             fmt::format("period_s = {:g} s is longer than the waveform ({:g} s)",
                                         w.table_period_s, w.table_t_s.back())));
  return w;
}

}  // namespace gmasim
