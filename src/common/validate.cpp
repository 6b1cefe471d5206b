// The validation layer (include/gmasim/model/validate.hpp, issue 8).
#include "gmasim/model/validate.hpp"

#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "gmasim/errors.hpp"

namespace gmasim {

namespace {

// {:g}, unless it rounds v to another number (1000.0001 is not "1000": issue 19, item 11).
std::string shown(double v) {
  std::string s = fmt::format("{:g}", v);
  if (std::isfinite(v) && std::strtod(s.c_str(), nullptr) != v) s = fmt::format("{}", v);
  return s;
}

std::string with_unit(double v, std::string_view unit) {
  return unit.empty() ? shown(v) : fmt::format("{} {}", shown(v), unit);
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

double require_positive_at_most(double v, double hi, std::string_view what, std::string_view unit) {
  require_finite(v, what, unit);
  if (!(v > 0.0 && v <= hi))
    fail(v, what, unit,
         fmt::format("must be in ({}, {}]", with_unit(0.0, unit), with_unit(hi, unit)));
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

std::optional<MemoryAvailable> memory_available() {
  std::optional<MemoryAvailable> best;
  if (std::FILE* f = std::fopen("/proc/meminfo", "r")) {
    char line[256];
    while (std::fgets(line, sizeof line, f)) {
      unsigned long long kb = 0;
      if (std::sscanf(line, "MemAvailable: %llu kB", &kb) == 1) {
        best = MemoryAvailable{static_cast<double>(kb) * 1024.0, "MemAvailable in /proc/meminfo"};
        break;
      }
    }
    std::fclose(f);
  }
  struct rlimit rl {};
  if (::getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    double used = 0.0;  // the address space in use: the first field of statm, in pages
    if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
      unsigned long long pages = 0;
      if (std::fscanf(f, "%llu", &pages) == 1)
        used = static_cast<double>(pages) * static_cast<double>(::sysconf(_SC_PAGESIZE));
      std::fclose(f);
    }
    const double left = std::max(0.0, static_cast<double>(rl.rlim_cur) - used);
    if (!best || left < best->bytes) best = MemoryAvailable{left, "RLIMIT_AS (ulimit -v)"};
  }
  return best;
}

void require_memory(double bytes, std::string_view what, std::string_view remedy) {
  const auto avail = memory_available();
  if (!avail || bytes <= avail->bytes) return;
  auto human = [](double b) {
    return b >= 1e9 ? fmt::format("{:.1f} GB", b / 1e9) : fmt::format("{:.0f} MB", b / 1e6);
  };
  throw InputError(fmt::format("{} needs about {} of memory; {} are available ({}): {}", what,
                               human(bytes), human(avail->bytes), avail->source, remedy));
}

std::string clip_for_message(std::string_view s, std::size_t max_chars) {
  if (s.size() <= max_chars) return std::string(s);
  const std::size_t head = max_chars * 2 / 3, tail = max_chars - head;
  return fmt::format("{} ... [{} characters omitted] ... {}", s.substr(0, head),
                     s.size() - head - tail, s.substr(s.size() - tail));
}

}  // namespace gmasim
