// Short power series shared by the step's laws: a degree-7 polynomial by Estrin's scheme and
// e^x from its Taylor series where |x| <= 1/64 (truncation below 1e-19 relative), and e^y from a
// nearby known value e^{y_prev} (exp_near: one exponential less where a Newton solve evaluates
// a law again close to its last point).
#pragma once

#include <cmath>

namespace gmasim::physics {

// c0 + c1 x + ... + c7 x^7 by Estrin's scheme (short dependency chains).
inline double polynomial7(double x, const double (&c)[8]) {
  const double x2 = x * x, x4 = x2 * x2;
  return (c[0] + c[1] * x) + x2 * (c[2] + c[3] * x) +
         x4 * ((c[4] + c[5] * x) + x2 * (c[6] + c[7] * x));
}

// e^x to (x^8 / 8!): below 1e-19 relative where |x| <= 1/64.
inline double exp_series7(double x) {
  constexpr double kExp[8] = {1.0,      1.0,       1.0 / 2,   1.0 / 6,
                              1.0 / 24, 1.0 / 120, 1.0 / 720, 1.0 / 5040};
  return polynomial7(x, kExp);
}

// A known exponential: e = e^y; y NaN: none.
struct ExpPoint {
  double y, e;
};
inline constexpr ExpPoint kNoExpPoint{__builtin_nan(""), 0.0};

// e^y from a known e^{y_prev} nearby (p): e^{y_prev} e^{y - y_prev} by exp_series7 where
// |y - y_prev| <= 1/64 (a few units in the last place from std::exp(y)), std::exp(y) otherwise
// or where nothing is known. p becomes the point (y, e^y).
inline double exp_near(double y, ExpPoint& p) {
  const double d = y - p.y;
  p.e = std::fabs(d) <= 1.0 / 64 ? p.e * exp_series7(d) : std::exp(y);
  p.y = y;
  return p.e;
}

// e^y where the last call with this p may have had the same y (a step's fixed decay over a run
// at one time step): p's value when y == p.y, std::exp(y) otherwise, bit for bit either way.
inline double exp_cached(double y, ExpPoint& p) {
  if (!(y == p.y)) p = {y, std::exp(y)};
  return p.e;
}

}  // namespace gmasim::physics
