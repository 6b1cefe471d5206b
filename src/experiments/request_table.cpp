// The rule check of the request tables (gmasim/experiments/request_table.hpp).
#include "gmasim/experiments/request_table.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "gmasim/errors.hpp"

namespace gmasim::fields {

void check_rule(double v, const Rule& rule, std::string_view name, std::string_view cli,
                std::string_view unit) {
  std::string what(name);
  if (!cli.empty()) what += fmt::format(" ({})", cli);
  const std::string u = unit.empty() || unit == "-" ? "" : fmt::format(" {}", unit);
  auto fail = [&](const std::string& why) {
    throw InputError(fmt::format("{} = {}{}: {}", what, v, u, why));
  };
  switch (rule.check) {
    case Check::Any:
      return;
    case Check::Finite:
      if (!std::isfinite(v)) fail("not a finite number");
      return;
    case Check::Positive:
      if (!(v > 0.0) || !std::isfinite(v)) fail("must be > 0");
      return;
    case Check::NonNegative:
      if (!(v >= 0.0) || !std::isfinite(v)) fail("must be >= 0");
      return;
    case Check::Range:
      if (!(v >= rule.lo && v <= rule.hi))
        fail(fmt::format("must be in [{:g}, {:g}]", rule.lo, rule.hi));
      return;
  }
}

}  // namespace gmasim::fields
