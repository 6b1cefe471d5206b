// The validation layer (issue 8, docs/reliability.md): every number a user can type is
// checked for finiteness and range before it becomes a count, a size or a file. Library entry
// points call these before any work, so the CLI, the Python module and C++ callers get the
// same InputError ("<what> = <value>: <rule>") and nothing converts an unchecked double.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace gmasim {

// Limits on what one request may ask for. They are far above any use of the tool (a run of
// 2e8 steps is 2000 s at the automatic 10 us step) and far below what would exhaust memory or
// time silently; exceeding one is an InputError that names the limit.
inline constexpr double kMaxSteps = 2e8;                   // time steps of one simulation
inline constexpr double kMaxRecordedRows = 2e7;            // rows of one recorded time series
inline constexpr double kMaxListValues = 1e5;              // values of one list/range flag
inline constexpr double kMaxGridRuns = 1e6;                // simulations of one sweep/track grid
inline constexpr double kMaxFrfPoints = 1e5;               // frequencies of one response
inline constexpr double kMaxPeriods = 1e6;                 // periods of one periodic run
inline constexpr std::size_t kMaxInputBytes = 256u << 20;  // one input file (256 MiB)
inline constexpr double kMaxTrackAmplitude_um = 1e4;       // a tracking reference (10 mm)

// v must be finite; returns v.
double require_finite(double v, std::string_view what, std::string_view unit = "");
// finite and > 0
double require_positive(double v, std::string_view what, std::string_view unit = "");
// finite and >= 0
double require_nonnegative(double v, std::string_view what, std::string_view unit = "");
// finite and lo <= v <= hi
double require_in(double v, double lo, double hi, std::string_view what,
                  std::string_view unit = "");

// A count from a double: x finite, 0 <= x <= max, then rounded to the nearest integer.
// The message names `what`, the value and the limit.
long checked_count(double x, double max, std::string_view what);
// ceil(x - 1e-9) as a count, with the same checks (steps = ceil(duration/dt)).
long checked_ceil_count(double x, double max, std::string_view what);
// An int from a user value: lo <= v <= hi.
int require_int_in(long v, long lo, long hi, std::string_view what);

// The number of fixed steps of length dt_s that cover duration_s (rounded to the nearest
// whole step), checked against kMaxSteps: "<n> steps of <dt> s over <duration> s: too many".
long checked_step_count(double duration_s, double dt_s, std::string_view what);

// A message clipped for display: a value or line longer than max_chars is shortened in the
// middle ("... [N characters omitted] ..."), so no error echoes a whole 1 MB input line.
std::string clip_for_message(std::string_view s, std::size_t max_chars = 200);

}  // namespace gmasim
