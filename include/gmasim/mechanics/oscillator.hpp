// The mechanics module (docs/layers.md, "The mechanics module"): the update of one oscillator
// row of eq. (15) over a time step, which step() calls for every rod. The chain's modes and
// the small-signal linearisation are in gmasim/mechanics/mechanics.hpp.
#pragma once

#include <cmath>

namespace gmasim::physics {

// The transition matrix of the free row, m e'' + c e' + k e = 0, over a step h: with
// A h = [[0, h], [-k h / m, -c h / m]] (trace tau = -c h / m, determinant delta = k h^2 / m),
// exp(A h) = f0 I + f1 A h. N = A h - tau/2 I has N^2 = u I, u = tau^2/4 - delta = -(w_d h)^2,
// so exp(N) = C I + S N with C = sum u^j / (2j)! (cos w_d h) and S = sum u^j / (2j+1)!
// (sin(w_d h) / (w_d h); cosh and sinh where u > 0, over-damped), and
//   f1 = e^(tau/2) S,   f0 = e^(tau/2) (C - tau/2 S).
// Where |u| <= 1/4 (w_d h <= 1/2: at least 12 steps per period) C and S are summed by Horner's
// rule to the term u^J / (2J)! with J = 5 up to |u| = 1/64 and 7 beyond (truncation below
// 1e-18): one exponential, no sincos or square root, every damping alike. valid = false
// beyond: the closed form.
struct OscillatorPropagator {
  double f0, f1;
  bool valid;
};
inline OscillatorPropagator oscillator_propagator(double tau, double delta) {
  const double half_tau = 0.5 * tau;
  const double u = half_tau * half_tau - delta;
  if (!(std::fabs(u) <= 0.25)) return {0.0, 0.0, false};
  // 1 / ((2j - 1) 2j) and 1 / (2j (2j + 1)), j = 1..7
  constexpr double kC[8] = {0.0,           1.0 / 2,        1.0 / (3 * 4),   1.0 / (5 * 6),
                            1.0 / (7 * 8), 1.0 / (9 * 10), 1.0 / (11 * 12), 1.0 / (13 * 14)};
  constexpr double kS[8] = {0.0,           1.0 / (2 * 3),   1.0 / (4 * 5),   1.0 / (6 * 7),
                            1.0 / (8 * 9), 1.0 / (10 * 11), 1.0 / (12 * 13), 1.0 / (14 * 15)};
  const int terms = std::fabs(u) <= 1.0 / 64 ? 5 : 7;
  double C = 1.0, S = 1.0;
  for (int j = terms; j >= 1; --j) {
    C = 1.0 + u * C * kC[j];
    S = 1.0 + u * S * kS[j];
  }
  const double E = std::exp(half_tau);
  return {E * (C - half_tau * S), E * S, true};
}

// Exact update of one diagonal row of eq. (15),  m x'' + c x' + k x = F(t),  over a step
// h with F linear from F0 to F1 (first-order hold) and m, c, k frozen over the step.
// The homogeneous part is propagated with its closed-form solution (under-, critically
// or over-damped; by its Taylor series where the step is short against the row's period and
// decay: oscillator_propagator), the ramp by its particular solution, so the update is exact
// for piecewise-linear forcing and unconditionally stable: the step is not limited by the
// 7-20 kHz mechanical modes. Updates x [m] and v [m/s].
inline void oscillator_step(double m, double c, double k, double F0, double F1, double h, double& x,
                            double& v) {
  const double g = (F1 - F0) / h;  // force rate [N/s]
  // Particular solution x_p(s) = (F0 + g s)/k - g c / k^2, v_p = g / k.
  const double inv_k = 1.0 / k;
  const double xp0 = (F0 - g * c * inv_k) * inv_k;
  const double vp = g * inv_k;
  const double e0 = x - xp0;
  const double ed0 = v - vp;
  double e1 = 0.0, ed1 = 0.0;
  const double inv_m = 1.0 / m;
  const double c_m = c * inv_m, k_m = k * inv_m;
  const OscillatorPropagator pr = oscillator_propagator(-c_m * h, k_m * h * h);
  if (pr.valid) {
    e1 = pr.f0 * e0 + pr.f1 * h * ed0;
    ed1 = pr.f0 * ed0 - pr.f1 * h * (k_m * e0 + c_m * ed0);
    const double xp1 = (F1 - g * c * inv_k) * inv_k;
    x = xp1 + e1;
    v = vp + ed1;
    return;
  }
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
  const double xp1 = (F1 - g * c * inv_k) * inv_k;
  x = xp1 + e1;
  v = vp + ed1;
}

}  // namespace gmasim::physics
