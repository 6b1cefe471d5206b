// The mechanics module (docs/layers.md, "The mechanics module"): the update of one oscillator
// row of eq. (15) over a time step, which step() calls for every rod. The chain's modes and
// the small-signal linearisation are in gmasim/mechanics/mechanics.hpp.
#pragma once

#include <cmath>

namespace gmasim::physics {

// Exact update of one diagonal row of eq. (15),  m x'' + c x' + k x = F(t),  over a step
// h with F linear from F0 to F1 (first-order hold) and m, c, k frozen over the step.
// The homogeneous part is propagated with its closed-form solution (under-, critically
// or over-damped), the ramp by its particular solution, so the update is exact for
// piecewise-linear forcing and unconditionally stable: the step is not limited by the
// 7-20 kHz mechanical modes. Updates x [m] and v [m/s].
inline void oscillator_step(double m, double c, double k, double F0, double F1, double h, double& x,
                            double& v) {
  const double g = (F1 - F0) / h;  // force rate [N/s]
  // Particular solution x_p(s) = (F0 + g s)/k - g c / k^2, v_p = g / k.
  const double xp0 = (F0 - g * c / k) / k;
  const double vp = g / k;
  const double e0 = x - xp0;
  const double ed0 = v - vp;
  const double wn = std::sqrt(k / m);
  const double zeta = c / (2.0 * std::sqrt(k * m));
  double e1 = 0.0, ed1 = 0.0;
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
  const double xp1 = (F1 - g * c / k) / k;
  x = xp1 + e1;
  v = vp + ed1;
}

}  // namespace gmasim::physics
