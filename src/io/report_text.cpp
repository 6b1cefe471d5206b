// The experiments' reports as text: one CSV per table (one row per point, column names with
// units) and one JSON document holding every table. The tables themselves are built in
// src/experiments/report.cpp.
#include <fmt/format.h>

#include <cmath>
#include <iterator>

#include "gmasim/io/io.hpp"
#include "io/json.hpp"

namespace gmasim {
namespace {

// A value that is not a finite number (not measured, not defined: a stepped-sine column of a
// linear-only response) is missing: null in JSON, an empty cell in CSV, never the ambiguous
// text "nan" or "inf". Numbers are the shortest text that reads back to the same double.
std::string csv_number(double v) {
  if (!std::isfinite(v)) return "";
  return fmt::format("{}", v);
}

void write_cell(io_detail::JsonWriter& w, const Cell& c) {
  if (c.is_bool) {
    w.boolean(c.text == "true");
  } else if (c.is_text) {
    w.string(c.text);
  } else {
    w.number(c.number);
  }
}

std::string csv_text(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"') out += '"';
    out += ch;
  }
  return out + "\"";
}

}  // namespace

std::string table_csv(const Table& t) {
  fmt::memory_buffer out;
  for (std::size_t c = 0; c < t.columns.size(); ++c)
    fmt::format_to(std::back_inserter(out), "{}{}", c ? "," : "", t.columns[c]);
  out.push_back('\n');
  for (const auto& row : t.rows) {
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (c) out.push_back(',');
      const Cell& cell = row[c];
      const std::string s = cell.is_text ? csv_text(cell.text) : csv_number(cell.number);
      out.append(s.data(), s.data() + s.size());
    }
    out.push_back('\n');
  }
  return fmt::to_string(out);
}

std::string report_json(const Report& r) {
  io_detail::JsonWriter w;
  w.begin_object();
  w.key("experiment").string(r.experiment);
  w.key("meta").begin_object();
  for (const auto& [name, cell] : r.meta) {
    w.key(name);
    write_cell(w, cell);
  }
  w.end_object();
  w.key("tables").begin_object();
  for (const Table& t : r.tables) {
    w.key(t.name).begin_object();
    w.key("columns").begin_array(io_detail::JsonLayout::Inline);
    for (const auto& c : t.columns) w.string(c);
    w.end_array();
    w.key("rows").begin_array();
    for (const auto& row : t.rows) {
      w.begin_object(io_detail::JsonLayout::Inline);
      for (std::size_t c = 0; c < row.size() && c < t.columns.size(); ++c) {
        w.key(t.columns[c]);
        write_cell(w, row[c]);
      }
      w.end_object();
    }
    w.end_array();
    w.end_object();
  }
  w.end_object();
  w.end_object();
  return w.text();
}

}  // namespace gmasim
