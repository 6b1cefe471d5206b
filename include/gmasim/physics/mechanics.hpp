// Mechanics and thermal expansion: eq. (15)-(21) and (24)-(28). SI units: N/m, N s/m, kg,
// m, Pa; temperatures named _C are in degrees Celsius.
#pragma once

#include <cmath>
#include <span>

#include "gmasim/physics/laws.hpp"

// The oscillator update of eq. (15), one law per header.
#include "gmasim/physics/oscillator.hpp"

namespace gmasim::physics {

// Eq. (17): axial stiffness of a rod or bar [N/m].  k = E A / l.
inline double axial_stiffness(double E_Pa, double area_m2, double length_m) {
  return E_Pa * area_m2 / length_m;
}

// Not in the paper (issue 37's joint reading, docs/model.md "The joints"): the compliance of a
// rod's bonded joints, a bond line of total thickness g and modulus E_j over the rod's section
// A, in series with the rod's l / (E A) [m/N].  c_j = g / (E_j A).
inline double joint_compliance(double gap_m, double modulus_Pa, double area_m2) {
  return gap_m / (modulus_Pa * area_m2);
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

}  // namespace gmasim::physics
