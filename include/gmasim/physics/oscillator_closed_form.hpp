// Eq. (15)'s free row in closed form and the constants of its propagator's series: the scalar
// helpers of the oscillator law (gmasim/physics/laws-inl.h, oscillator_propagator and
// oscillator_step), which the lanes call lane by lane where a step is beyond the series' caps.
#pragma once

#include <cmath>

namespace gmasim::physics {

inline constexpr double kOscillatorSeriesUnder = 65536.0;  // 4^8
inline constexpr double kOscillatorCos[8] = {
    1.0,         1.0 / 2,       1.0 / 24,          1.0 / 720,
    1.0 / 40320, 1.0 / 3628800, 1.0 / 479001600.0, 1.0 / 87178291200.0};
inline constexpr double kOscillatorSinc[8] = {
    1.0,          1.0 / 6,          1.0 / 120,          1.0 / 5040,
    1.0 / 362880, 1.0 / 39916800.0, 1.0 / 6227020800.0, 1.0 / 1307674368000.0};

// The closed form of the free row over h (under-, critically or over-damped)
// from (e0, e0'): where the series of oscillator_propagator does not apply (over-damped
// beyond |u| = 4, under-damped beyond kOscillatorSeriesUnder: w_d h > 256).
[[gnu::noinline]] inline void oscillator_free_closed_form(double m, double c, double k, double h,
                                                          double e0, double ed0, double &e1,
                                                          double &ed1) {
  const double wn = std::sqrt(k / m);
  const double zeta = c / (2.0 * std::sqrt(k * m));
  if (zeta < 1.0 - 1e-9) {
    const double wd = wn * std::sqrt(1.0 - zeta * zeta);
    const double decay = std::exp(-zeta * wn * h);
    const double cs = std::cos(wd * h), sn = std::sin(wd * h);
    const double B = (ed0 + zeta * wn * e0) / wd;
    e1 = decay * (e0 * cs + B * sn);
    ed1 = decay * (ed0 * cs - (wn * wn * e0 + zeta * wn * ed0) / wd * sn);
  } else if (zeta > 1.0 + 1e-9) {
    const double s = wn * std::sqrt(zeta * zeta - 1.0);
    const double r1 = -zeta * wn + s, r2 = -zeta * wn - s;
    const double A1 = (ed0 - r2 * e0) / (r1 - r2), A2 = (r1 * e0 - ed0) / (r1 - r2);
    const double E1 = std::exp(r1 * h), E2 = std::exp(r2 * h);
    e1 = A1 * E1 + A2 * E2;
    ed1 = A1 * r1 * E1 + A2 * r2 * E2;
  } else {
    const double E = std::exp(-wn * h);
    const double B = ed0 + wn * e0;
    e1 = (e0 + B * h) * E;
    ed1 = (B - wn * (e0 + B * h)) * E;
  }
}

}  // namespace gmasim::physics
