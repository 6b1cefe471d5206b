// Eq. (15), one law: the update of one oscillator row over a time step, which step() calls for
// every rod (a physics law, below the model: docs/layers.md). The chain's modes and the
// small-signal linearisation, which take a Model, are in gmasim/mechanics/mechanics.hpp.
#pragma once

#include <cmath>

#include "gmasim/physics/series.hpp"

namespace gmasim::physics {

// The transition matrix of the free row, m e'' + c e' + k e = 0, over a step h:
// with A h = [[0, h], [-k h / m, -c h / m]] (trace tau = -c h / m, determinant
// delta = k h^2 / m), exp(A h) = f0 I + f1 A h. N = A h - tau/2 I has N^2 = u
// I, u = tau^2/4 - delta = -(w_d h)^2, so exp(N) = C I + S N with C = sum u^j /
// (2j)! (cos w_d h) and S = sum u^j / (2j+1)! (sin(w_d h) / (w_d h); cosh and
// sinh where u > 0, over-damped), and
//   f1 = e^(tau/2) S,   f0 = e^(tau/2) (C - tau/2 S).
// C and S are summed to u^7 (truncation below 1e-18; Estrin's scheme) at u / 4^n, n the
// fewest halvings that bring it within 1/4 (none where w_d h <= 1/2: at least 12 steps per
// period), and doubled n times (oscillator_series_doubled: exp(N) = exp(N/2)^2); e^(tau/2) by
// its series to (tau/2)^7 where |tau/2| <= 1/64 (below 1e-19) and by std::exp beyond: no sincos
// or square root, every damping alike. Over-damped (u > 0) up to |u| = 4 (w_d h <= 2: cosh and
// sinh grow with u and cancel against e^(tau/2)); under-damped (u < 0) up to |u| =
// kOscillatorSeriesUnder (w_d h <= 256, eight halvings): the doublings turn (C, S w_d h) as
// rotations, their rounding growing as 2^n -- 5.6e-14 of e^(tau/2) at the cap against a long
// double reference, where the closed form is 1.7e-14 off (tests/test_physics.cpp,
// Oscillator.LongStepsTakeTheSeriesToItsCap). A step of many of the row's periods (the
// identification's 200 steps a period at 10 Hz: w_d h ~ 40 for the 8-13 kHz rods) takes the
// series; valid = false beyond the caps: the closed form.
inline constexpr double kOscillatorSeriesUnder = 65536.0;  // 4^8
struct OscillatorPropagator {
  double f0, f1;
  bool valid;
};
inline constexpr double kOscillatorCos[8] = {
    1.0,         1.0 / 2,       1.0 / 24,          1.0 / 720,
    1.0 / 40320, 1.0 / 3628800, 1.0 / 479001600.0, 1.0 / 87178291200.0};
inline constexpr double kOscillatorSinc[8] = {
    1.0,          1.0 / 6,          1.0 / 120,          1.0 / 5040,
    1.0 / 362880, 1.0 / 39916800.0, 1.0 / 6227020800.0, 1.0 / 1307674368000.0};
// One doubling: (C, S) of exp(N / 2), whose (N / 2)^2 = u_half I, to those of exp(N) =
// exp(N / 2)^2 = (C^2 + u_half S^2) I + (C S) N.
inline void oscillator_series_doubled(double u_half, double &C, double &S) {
  const double c = C;
  C = c * c + u_half * (S * S);
  S = c * S;
}
// decay: the last e^(tau/2) taken by std::exp (physics::exp_cached; a run's step repeats it).
inline OscillatorPropagator oscillator_propagator(double tau, double delta, ExpPoint &decay) {
  const double half_tau = 0.5 * tau;
  const double u = half_tau * half_tau - delta;
  const double au = std::fabs(u);
  if (!(au <= 4.0) && !(u < 0.0 && au <= kOscillatorSeriesUnder)) return {0.0, 0.0, false};
  // The halvings: none where |u| <= 1/4, one (u / 4) to |u| = 1, two (u / 16) to 4, ...
  // (exact: powers of two).
  int halvings = 0;
  double us = u;
  while (std::fabs(us) > 0.25) {
    us *= 0.25;
    ++halvings;
  }
  double C = polynomial7(us, kOscillatorCos), S = polynomial7(us, kOscillatorSinc);
  // exp(N / 2^j) to exp(N / 2^(j-1)), j = halvings .. 1: (N / 2^j)^2 = u / 4^j
  double u_half = us;
  for (int j = halvings; j >= 1; --j, u_half *= 4.0) oscillator_series_doubled(u_half, C, S);
  const double E =
      std::fabs(half_tau) <= 1.0 / 64 ? exp_series7(half_tau) : exp_cached(half_tau, decay);
  return {E * (C - half_tau * S), E * S, true};
}
inline OscillatorPropagator oscillator_propagator(double tau, double delta) {
  ExpPoint none = kNoExpPoint;
  return oscillator_propagator(tau, delta, none);
}

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

// Exact update of one diagonal row of eq. (15),  m x'' + c x' + k x = F(t),
// over a step h with F linear from F0 to F1 (first-order hold) and m, c, k
// frozen over the step. The homogeneous part is propagated with its closed-form
// solution (under-, critically or over-damped; by its series where the step is
// short against the row's period: oscillator_propagator), the ramp by its
// particular solution, so the update is exact for piecewise-linear forcing and
// unconditionally stable: the step is not limited by the 7-20 kHz mechanical
// modes. Updates x [m] and v [m/s].
// inv_m = 1/m; decay: oscillator_propagator's (the row's last e^(tau/2)).
inline void oscillator_step(double m, double inv_m, double c, double k, double F0, double F1,
                            double h, double &x, double &v, ExpPoint &decay) {
  const double g = (F1 - F0) / h;  // force rate [N/s]
  // Particular solution x_p(s) = (F0 + g s)/k - g c / k^2, v_p = g / k.
  const double inv_k = 1.0 / k;
  const double xp0 = (F0 - g * c * inv_k) * inv_k;
  const double vp = g * inv_k;
  const double e0 = x - xp0;
  const double ed0 = v - vp;
  double e1 = 0.0, ed1 = 0.0;
  const double c_m = c * inv_m, k_m = k * inv_m;
  const OscillatorPropagator pr = oscillator_propagator(-c_m * h, k_m * h * h, decay);
  if (pr.valid) [[likely]] {
    e1 = pr.f0 * e0 + pr.f1 * h * ed0;
    ed1 = pr.f0 * ed0 - pr.f1 * h * (k_m * e0 + c_m * ed0);
  } else {
    oscillator_free_closed_form(m, c, k, h, e0, ed0, e1, ed1);
  }
  const double xp1 = (F1 - g * c * inv_k) * inv_k;
  x = xp1 + e1;
  v = vp + ed1;
}

inline void oscillator_step(double m, double c, double k, double F0, double F1, double h, double &x,
                            double &v) {
  ExpPoint none = kNoExpPoint;
  oscillator_step(m, 1.0 / m, c, k, F0, F1, h, x, v, none);
}

}  // namespace gmasim::physics
