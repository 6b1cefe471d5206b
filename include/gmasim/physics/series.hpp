// Short power series shared by the step's laws: a degree-7 polynomial by Estrin's scheme, e^x
// from its Taylor series where |x| <= 1/64 (truncation below 1e-19 relative) or, to degree 10,
// where |x| <= 1/8 (below 3e-18), and e^y from a known anchor value e^{y_a} (exp_near: one
// exponential less where a law is evaluated again close to an earlier point, within a Newton
// solve and from one step to the next).
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

// e^x - 1 to (x^11 / 11!): below 3e-18 relative to e^x where |x| <= 1/8.
inline double expm1_series10(double x) {
  const double x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
  return x * (((1.0 + x * (1.0 / 2)) + x2 * (1.0 / 6 + x * (1.0 / 24))) +
              x4 * ((1.0 / 120 + x * (1.0 / 720)) + x2 * (1.0 / 5040 + x * (1.0 / 40320))) +
              x8 * (1.0 / 362880 + x * (1.0 / 3628800)));
}

// cos(pi m / 2) for |m| <= 1 from its Taylor series in t = m^2 to t^10 (truncation below 2e-17,
// absolute; rounding a few 1e-16 absolute, where std::cos(0.5 * pi * m) is itself 6e-17 off at
// m = 1 through the rounding of pi/2): no range reduction. std::cos elsewhere.
inline double cos_half_pi(double m) {
  if (!(std::fabs(m) <= 1.0)) return std::cos(1.5707963267948966 * m);
  const double t = m * m, t2 = t * t, t4 = t2 * t2, t8 = t4 * t4;
  return ((1.0 - 1.2337005501361697 * t) + t2 * (0.25366950790104803 - 0.02086348076335296 * t)) +
         t4 * ((0.0009192602748394266 - 2.5202042373060607e-05 * t) +
               t2 * (4.710874778818172e-07 - 6.386603083791852e-09 * t)) +
         t8 * ((6.565963114979473e-11 - 5.294400200734623e-13 * t) + t2 * 3.437739179098607e-15);
}

// A known exponential: e = e^y; y NaN: none.
struct ExpPoint {
  double y, e;
};
inline constexpr ExpPoint kNoExpPoint{__builtin_nan(""), 0.0};

// e^y from an anchor a = (y_a, e^{y_a}) that std::exp computed: e^{y_a} + e^{y_a} (e^d - 1),
// d = y - y_a, by expm1_series10 where |d| <= 1/8; otherwise (or where a.y is NaN: no anchor)
// std::exp(y), and a becomes (y, e^y). The anchor moves only there, so every value is one series
// and two roundings away from a std::exp value (within 2 units in the last place of std::exp(y),
// test Series.ExpNearIsWithinAFewUlp), however long the anchor is kept: over a Newton solve's
// iterates and from step to step (RodState::ja_exp, prestress_exp).
inline double exp_near(double y, ExpPoint& a) {
  const double d = y - a.y;
  if (std::fabs(d) <= 1.0 / 8) return a.e + a.e * expm1_series10(d);
  a = {y, std::exp(y)};
  return a.e;
}

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

// e^y where the last call with this p may have had the same y (a step's fixed decay over a run
// at one time step): p's value when y == p.y, std::exp(y) otherwise, bit for bit either way.
inline double exp_cached(double y, ExpPoint& p) {
  if (!(y == p.y)) p = {y, std::exp(y)};
  return p.e;
}

}  // namespace gmasim::physics
