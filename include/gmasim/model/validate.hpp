// The validation layer (issue 8, docs/reliability.md): every number a user can type is
// checked for finiteness and range before it becomes a count, a size or a file. Library entry
// points call these before any work, so the CLI, the Python module and C++ callers get the
// same InputError ("<what> = <value>: <rule>") and nothing converts an unchecked double.
#pragma once

#include <cstddef>
#include <optional>
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
// Counts that become threads (issue 19, item 4): worker threads of one command (--threads) and
// islands of identify (each a thread), and identify's work: individuals per island, generations,
// and evaluations of one rank's search (islands x population x generations).
inline constexpr int kMaxThreads = 1024;
inline constexpr int kMaxIslands = 256;
inline constexpr int kMaxPopulation = 100000;
inline constexpr int kMaxGenerations = 1000000;
inline constexpr double kMaxGaEvaluations = 1e8;
// The time steps step() supports (docs/model.md, "Time step"; issue 19, item 2). Below
// kMinStepDt_s the state is no longer held at constant current: measured on the built-in model,
// y stays within 1e-14 relative from 1e-5 s down to 1e-20 s and jumps near 1e-24 s (the eddy
// and mechanical updates cancel in floating point); the limit keeps a factor 1e8 from that and
// is far below any physical time scale (the mechanical modes: 50-150 us). Every step grid and
// the Stepper refuse a shorter step. A step a user asks for (--dt, dt_s) must also be at most
// kMaxStepDt_s: a longer one resolves neither the eddy currents nor the mechanical modes.
inline constexpr double kMinStepDt_s = 1e-12;
inline constexpr double kMaxStepDt_s = 1e-3;
// A periodic run with a step the user gave must hold at least this many steps per period: below
// it the loop moves by more than 1 % when dt is halved (measured at 100 Hz: 40 -> 80 steps
// moves the hysteresis 4.7 %, 80 -> 160 moves it 0.45 %). The automatic rule takes 2000.
inline constexpr double kMinStepsPerPeriod = 100;
// The metrics of a run need at least this many recorded samples in their window.
inline constexpr double kMinMetricSamples = 3;

// v must be finite; returns v.
double require_finite(double v, std::string_view what, std::string_view unit = "");
// finite and > 0
double require_positive(double v, std::string_view what, std::string_view unit = "");
// finite and >= 0
double require_nonnegative(double v, std::string_view what, std::string_view unit = "");
// finite and lo <= v <= hi
double require_in(double v, double lo, double hi, std::string_view what,
                  std::string_view unit = "");
// finite and 0 < v <= hi ("must be in (0 Hz, 1e+06 Hz]")
double require_positive_at_most(double v, double hi, std::string_view what,
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

// Memory (issue 19, item 7): what this process may still allocate, in bytes: MemAvailable of
// /proc/meminfo, and, when RLIMIT_AS is set, that limit less the address space already in use
// (/proc/self/statm); the smaller of the two, and which one it is ("MemAvailable",
// "RLIMIT_AS (ulimit -v)"). nullopt when neither can be read.
struct MemoryAvailable {
  double bytes = 0.0;
  std::string source;
};
std::optional<MemoryAvailable> memory_available();
// Refuses (InputError) a request whose estimated memory `bytes` exceeds what is available:
// "<what> needs about 28.1 GB of memory; 5.2 GB are available (MemAvailable): <remedy>".
void require_memory(double bytes, std::string_view what, std::string_view remedy);

// A message clipped for display: a value or line longer than max_chars is shortened in the
// middle ("... [N characters omitted] ..."), so no error echoes a whole 1 MB input line.
std::string clip_for_message(std::string_view s, std::size_t max_chars = 200);

}  // namespace gmasim
