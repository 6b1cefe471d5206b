// The condition of a measurement file (docs/data.md): the keys of its header comments and of
// its TOML sidecar, checked against each other and against the record
// (measurement_condition.cpp; the CSV reader is measurements.cpp).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "gmasim/identify/identify.hpp"

namespace gmasim::identify_detail {

struct KeyValue {
  std::string text;  // as written (numbers are re-parsed)
  double number = 0.0;
  std::string file;
  long line = 0;
};
using KeyMap = std::map<std::string, KeyValue>;

// A finite number, or the reason it is not one.
std::optional<std::string> parse_number(std::string_view cell, double& v);

// "# key = value" / "# key: value" in a CSV comment; free-text comments are ignored.
void read_comment_key(std::string_view comment, const std::string& path, long line, KeyMap& keys);

// The sidecar of a CSV file: the same name with the extension .toml.
std::string sidecar_path(const std::string& csv);
// Adds the sidecar's keys; a key the CSV also gives must have the same value.
void read_sidecar(const std::string& path, KeyMap& keys);

// The record's condition from its keys; the record m is read (t_s, drive, response, flux_T,
// the column kinds and condition.quasi_static). Throws InputError at the file:line of the
// key at fault (header_line of `path` for a missing one).
MeasurementCondition make_condition(const KeyMap& keys, const Measurement& m,
                                    const std::string& path, long header_line);

}  // namespace gmasim::identify_detail
