// Rows that several request tables share (gmasim/experiments/request_table.hpp), spelled once:
// the run length in periods and the time step, with one rule each; a table gives the help
// (what the periods measure there) and where the row shows.
#pragma once

#include <string_view>

#include "gmasim/experiments/request_table.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim::fields {

inline constexpr Rule kPeriods = in(1.0, kMaxPeriods);

// --periods: a run's length in periods of its drive [-].
template <class R>
constexpr auto periods_row(std::string_view help, unsigned where) {
  return field<R>("periods", "-", kPeriods, "--periods", help, where, GMASIM_REF(R, periods));
}
// --dt: the time step [s]; 0 means the command's automatic rule (its help says which).
template <class R>
constexpr auto dt_row(std::string_view help, unsigned where) {
  return field<R>("dt_s", "s", nonnegative(), "--dt", help, where, GMASIM_REF(R, dt_s));
}

}  // namespace gmasim::fields
