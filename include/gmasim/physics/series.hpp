// Short power series shared by the step's laws: a degree-7 polynomial by Estrin's scheme, e^x
// from its Taylor series where |x| <= 1/64 (truncation below 1e-19 relative) or, to degree 10,
// where |x| <= 1/8 (below 3e-18), and e^y from a known anchor value e^{y_a} (exp_near: one
// exponential less where a law is evaluated again close to an earlier point, within a Newton
// solve and from one step to the next).
#pragma once

#include <cmath>

#include "gmasim/physics/laws.hpp"

namespace gmasim::physics {

// e^y near the last value of the same Newton solve: from `recent` (y_r, e^{y_r}), a value
// exp_near(y_r, a) returned, as e^{y_r} (1 + d + d^2/2 + d^3/6), d = y - y_r, where |d| <= 2^-13
// (truncation below 1e-17 relative; the consistent state's iterates after the first move the
// law's exponents by 1e-5 at most); otherwise exp_near(y, a), and recent becomes (y, that value).
// recent holds only exp_near's values and lives for one solve (JilesAthertonLaw::MoveStart), so
// every value is at most two short series and four roundings from a std::exp value.
inline double exp_near(double y, ExpPoint& a, ExpPoint& recent) {
  const double d = y - recent.y;
  if (std::fabs(d) <= 1.0 / 8192)
    return recent.e + recent.e * (d * (1.0 + d * (1.0 / 2 + d * (1.0 / 6))));
  recent = {y, exp_near(y, a)};
  return recent.e;
}

}  // namespace gmasim::physics
