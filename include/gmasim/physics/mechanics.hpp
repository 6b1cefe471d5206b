// Mechanics and thermal expansion: eq. (15)-(21) and (24)-(28). SI units: N/m, N s/m, kg,
// m, Pa; temperatures named _C are in degrees Celsius.
#pragma once

#include <cmath>
#include <span>

namespace gmasim::physics {

// Eq. (17): axial stiffness of a rod or bar [N/m].  k = E A / l.
inline double axial_stiffness(double E_Pa, double area_m2, double length_m) {
  return E_Pa * area_m2 / length_m;
}

// Eq. (18) and eq. (28): springs or dampers in series: (sum 1/k_i)^-1.
inline double series_combination(std::span<const double> values) {
  double s = 0.0;
  for (double v : values) s += 1.0 / v;
  return 1.0 / s;
}

// Eq. (19), the E_t^T law of ref. 32: sleeve modulus E_t^T = E_t - 0.10667 GPa/degC * T
// [Pa]; T in degC as printed. The slope is a model parameter.
inline double sleeve_modulus(double Et_Pa, double dEt_dT_Pa_per_C, double T_C) {
  return Et_Pa - dEt_dT_Pa_per_C * T_C;
}

// Eq. (19): sleeve stiffness from its segments [N/m].
//   k_t^T = (sum_i l_i / (E_t^T A_i))^-1
inline double sleeve_stiffness(double EtT_Pa, std::span<const double> lengths_m,
                               std::span<const double> areas_m2) {
  double s = 0.0;
  for (std::size_t i = 0; i < lengths_m.size(); ++i) s += lengths_m[i] / (EtT_Pa * areas_m2[i]);
  return 1.0 / s;
}

// Eq. (24): diagonal mass of one rod's oscillator [kg]: m_rod/3 + m_lr.
inline double oscillator_mass(double rod_mass_kg, double load_mass_kg) {
  return rod_mass_kg / 3.0 + load_mass_kg;
}

// Eq. (21): thermal expansion of the stack [m].
//   x_T = (alpha_G l_G + alpha_M l_M + alpha_s l_s - alpha_t l_t) dT
inline double thermal_expansion(double alphaG_lG_m_per_K, double alphaM_lM_m_per_K,
                                double alphas_ls_m_per_K, double alphat_lt_m_per_K, double dT_K) {
  return (alphaG_lG_m_per_K + alphaM_lM_m_per_K + alphas_ls_m_per_K - alphat_lt_m_per_K) * dT_K;
}

// Linear dimension at temperature: l^T = l (1 + alpha dT) (the l_G^T, A_G^T, r^T of
// eq. 2, 7, 17 and 19).
inline double expanded_length(double length_m, double alpha_per_K, double dT_K) {
  return length_m * (1.0 + alpha_per_K * dT_K);
}

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
