// The validation layer (include/gmasim/validate.hpp, issue 8).
#include "gmasim/validate.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "gmasim/errors.hpp"

namespace gmasim {

namespace {

std::string with_unit(double v, std::string_view unit) {
  return unit.empty() ? fmt::format("{:g}", v) : fmt::format("{:g} {}", v, unit);
}

[[noreturn]] void fail(double v, std::string_view what, std::string_view unit,
                       std::string_view rule) {
  throw InputError(fmt::format("{} = {}: {}", what, with_unit(v, unit), rule));
}

}  // namespace

double require_finite(double v, std::string_view what, std::string_view unit) {
  if (!std::isfinite(v)) fail(v, what, unit, "must be a finite number");
  return v;
}

double require_positive(double v, std::string_view what, std::string_view unit) {
  require_finite(v, what, unit);
  if (!(v > 0.0)) fail(v, what, unit, "must be > 0");
  return v;
}

double require_nonnegative(double v, std::string_view what, std::string_view unit) {
  require_finite(v, what, unit);
  if (!(v >= 0.0)) fail(v, what, unit, "must be >= 0");
  return v;
}

double require_in(double v, double lo, double hi, std::string_view what, std::string_view unit) {
  require_finite(v, what, unit);
  if (!(v >= lo && v <= hi))
    fail(v, what, unit,
         fmt::format("must be in [{}, {}]", with_unit(lo, unit), with_unit(hi, unit)));
  return v;
}

long checked_count(double x, double max, std::string_view what) {
  if (!std::isfinite(x)) throw InputError(fmt::format("{} = {:g}: not a finite count", what, x));
  if (x < 0.0) throw InputError(fmt::format("{} = {:g}: must be >= 0", what, x));
  if (x > max) throw InputError(fmt::format("{} = {:.6g}: too many (limit {:g})", what, x, max));
  return std::lround(x);
}

long checked_ceil_count(double x, double max, std::string_view what) {
  if (!std::isfinite(x)) throw InputError(fmt::format("{} = {:g}: not a finite count", what, x));
  return checked_count(std::ceil(x - 1e-9), max, what);
}

int require_int_in(long v, long lo, long hi, std::string_view what) {
  if (v < lo || v > hi)
    throw InputError(fmt::format("{} = {}: must be in [{}, {}]", what, v, lo, hi));
  return static_cast<int>(v);
}

long checked_step_count(double duration_s, double dt_s, std::string_view what) {
  require_positive(duration_s, fmt::format("{}: duration", what), "s");
  require_positive(dt_s, fmt::format("{}: time step", what), "s");
  const double n = duration_s / dt_s;
  if (!(n <= kMaxSteps))
    throw InputError(fmt::format(
        "{}: {:.4g} steps of {:g} s over {:g} s: too many (limit {:g}); raise the time step or "
        "shorten the run",
        what, n, dt_s, duration_s, kMaxSteps));
  return std::max(1L, std::lround(n));
}

std::string clip_for_message(std::string_view s, std::size_t max_chars) {
  if (s.size() <= max_chars) return std::string(s);
  const std::size_t head = max_chars * 2 / 3, tail = max_chars - head;
  return fmt::format("{} ... [{} characters omitted] ... {}", s.substr(0, head),
                     s.size() - head - tail, s.substr(s.size() - tail));
}

}  // namespace gmasim
