// Internal: JSON string and number text shared by metrics.json (io/output.cpp) and the
// experiment reports (experiments/report.cpp). Not part of the public API.
#pragma once

#include <string>
#include <string_view>

namespace gmasim::io_detail {

// How json_string writes backspace and form feed: "\b", "\f" (metrics.json) or "\u0008",
// "\u000c" (experiment reports).
enum class BackspaceFormFeed { Short, Unicode };

// `s` as a quoted JSON string: '"', '\', newline, carriage return and tab (and, per `bf`,
// backspace and form feed) by their short escapes, the other control characters and DEL as
// \u00XX; UTF-8 passes through unchanged.
std::string json_string(std::string_view s, BackspaceFormFeed bf);

// The shortest representation that reads back to the same double; null for NaN and Inf
// (JSON has neither).
std::string json_number(double v);

}  // namespace gmasim::io_detail
