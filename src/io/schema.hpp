// Internal: the text helpers of model files (src/io, and identify's fitted model) on top of
// the schema (model/schema.hpp). Not part of the public API.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "model/schema.hpp"

namespace gmasim::schema {

// The text of a trailing "# comment" of one line (without '#', trimmed); '#' inside
// basic or literal strings is skipped. Empty if there is none.
std::string trailing_comment(std::string_view line);

// Where the value of `leaf = value` sits on one line of a model file (a plain line or an
// inline table): [begin, end) of the value text; nullopt if the line has no `leaf =`.
struct ValueSpan {
  std::size_t begin, end;
};
std::optional<ValueSpan> value_span(std::string_view line, std::string_view leaf);

// A number as TOML text that reads back as the same double (17 significant digits at
// most; always a float literal: "3.0", "1e-05").
std::string toml_float(double v);

}  // namespace gmasim::schema
