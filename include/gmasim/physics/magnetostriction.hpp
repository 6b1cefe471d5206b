// Prestressed magnetostriction, the Delta-E effect and the rod force: eq. (11)-(14).
// SI units: stresses and moduli in Pa, magnetisation as the reduced m = M / M_s^T.
#pragma once

#include <cmath>

#include "gmasim/physics/magnetic.hpp"

namespace gmasim::physics {

// M-independent parts of eq. (13), fixed by stress and temperature (precomputed once
// per Conditions):
//   u = (sigma - sigma0)/sigma_lambda
//   rotation_compliance = 3 lambda_s / (4 sigma_lambda) sech^2 u               [1/Pa]
//   coupling = (3 lambda_s / 2)(1 - tanh u) + 2 beta dT                         [-]
struct DeltaETerms {
  double inverse_Es_per_Pa;  // 1/E_s, the saturated (M = M_s) modulus
  double rotation_compliance_per_Pa;
  double coupling;
  double mu0_Ms2_over_chi_m_J_per_m3;  // mu0 pi M_s^T/(2k) = mu0 (M_s^T)^2 / chi_m (eq. 5)
  double S_J_per_m3;                   // stress_energy_term(), as in eq. (3)
};

inline DeltaETerms delta_e_terms(double Es_Pa, double lambda_s, double sigma_Pa,
                                 double sigma_lambda_Pa, double beta_per_K, double dT_K,
                                 double MsT_A_per_m, double chi_m, double S_J_per_m3) {
  const double u = (sigma_Pa - sigma0_of(sigma_lambda_Pa)) / sigma_lambda_Pa;
  const double ch = std::cosh(u);
  DeltaETerms d{};
  d.inverse_Es_per_Pa = 1.0 / Es_Pa;
  d.rotation_compliance_per_Pa = 3.0 * lambda_s / (4.0 * sigma_lambda_Pa) / (ch * ch);
  d.coupling = 1.5 * lambda_s * (1.0 - std::tanh(u)) + 2.0 * beta_per_K * dT_K;
  d.mu0_Ms2_over_chi_m_J_per_m3 = kMu0 * MsT_A_per_m * MsT_A_per_m / chi_m;
  d.S_J_per_m3 = S_J_per_m3;
  return d;
}

// Eq. (13): Delta-E modulus E_G^{M,T,sigma} [Pa] at reduced magnetisation m = M/M_s^T.
//   1/E = 1/E_s + rot (1 - m^2) + coupling^2 m^2 / [mu0 Ms^2/chi_m sec^2(pi m/2) - S]
// The last term is evaluated multiplied through by cos^2(pi m/2), so that m = 1 (where
// sec^2 is infinite) gives E = E_s exactly; cos(pi m/2) by its series (cos_half_pi).
// delta_e_compliance is 1/E, the bracket itself (the step multiplies by it where eq. 11-12 and
// 17 divide by E).
inline double delta_e_compliance(double m, const DeltaETerms& d) {
  const double c = cos_half_pi(m);
  const double c2 = c * c;
  const double m2 = m * m;
  const double third =
      d.coupling * d.coupling * m2 * c2 / (d.mu0_Ms2_over_chi_m_J_per_m3 - c2 * d.S_J_per_m3);
  return d.inverse_Es_per_Pa + d.rotation_compliance_per_Pa * (1.0 - m2) + third;
}
inline double delta_e_modulus(double m, const DeltaETerms& d) {
  return 1.0 / delta_e_compliance(m, d);
}

// Eq. (12): saturation and maximum magnetostrictive stress [Pa].
inline double saturation_stress(double lambda_s, double E_Pa) { return 0.5 * lambda_s * E_Pa; }
inline double maximum_stress(double lambda_s, double E_Pa) { return 1.5 * lambda_s * E_Pa; }

// Eq. (11): prestress factor f(sigma_p) of lambda = f lambda_s m^2, with sigma_p the
// magnitude of the compressive prestress [Pa]:
//   f = 1 + 1/2 tanh(2 sigma_p / sigma_s)                          sigma_p <= sigma_s
//   f = (1 - (sigma_p - sigma_s)/sigma_max)(1 + 1/2 tanh(2 sigma_p/sigma_s))  otherwise
// tanh u from one exponential, sign(u) (1 - e^{-2|u|}) / (1 + e^{-2|u|}): its absolute error is
// a few 1e-16 (not its relative error near u = 0), all eq. (11) needs beside 1 (std::tanh goes
// through expm1, about three times the cost of exp).
inline double tanh_from_exp(double u, double e) {  // e = exp(-2|u|)
  const double t = (1.0 - e) / (1.0 + e);
  return u < 0.0 ? -t : t;
}
inline double tanh_absolute(double u) { return tanh_from_exp(u, std::exp(-2.0 * std::fabs(u))); }
// The same with its exponential from an anchor nearby (p, exp_near: the step's last one).
inline double tanh_absolute_near(double u, ExpPoint& p) {
  return tanh_from_exp(u, exp_near(-2.0 * std::fabs(u), p));
}

// The factor at 2 sigma_p / sigma_s = two_sp_over_ss (given: the step forms it from 1/E).
// tanh_2sp_ss: tanh(2 sigma_p / sigma_s) (tanh_absolute).
inline double prestress_factor_from_tanh(double tanh_2sp_ss, double sigma_p_Pa, double sigma_s_Pa,
                                         double sigma_max_Pa) {
  const double base = 1.0 + 0.5 * tanh_2sp_ss;
  if (sigma_p_Pa <= sigma_s_Pa) return base;
  return (1.0 - (sigma_p_Pa - sigma_s_Pa) / sigma_max_Pa) * base;
}
inline double prestress_factor_at(double two_sp_over_ss, double sigma_p_Pa, double sigma_s_Pa,
                                  double sigma_max_Pa) {
  return prestress_factor_from_tanh(tanh_absolute(two_sp_over_ss), sigma_p_Pa, sigma_s_Pa,
                                    sigma_max_Pa);
}
inline double prestress_factor(double sigma_p_Pa, double sigma_s_Pa, double sigma_max_Pa) {
  return prestress_factor_at(2.0 * sigma_p_Pa / sigma_s_Pa, sigma_p_Pa, sigma_s_Pa, sigma_max_Pa);
}

// Eq. (11)-(12): magnetostrictive strain [-] with the stress thresholds of eq. (12)
// taken at the current modulus E_G; inv_E_per_Pa = 1/E_G (delta_e_compliance), so that
// 2 sigma_p / sigma_s = (4 sigma_p / lambda_s) / E_G is a product.
// The step's: tanh's exponential from the anchor `near` (tanh_absolute_near; RodState::
// prestress_exp), a few units in the last place from magnetostriction's.
inline double magnetostriction_near(double m, double lambda_s, double sigma_p_Pa, double E_Pa,
                                    double inv_E_per_Pa, ExpPoint& near) {
  const double f = prestress_factor_from_tanh(
      tanh_absolute_near(4.0 * sigma_p_Pa / lambda_s * inv_E_per_Pa, near), sigma_p_Pa,
      saturation_stress(lambda_s, E_Pa), maximum_stress(lambda_s, E_Pa));
  return f * lambda_s * m * m;
}
inline double magnetostriction(double m, double lambda_s, double sigma_p_Pa, double E_Pa,
                               double inv_E_per_Pa) {
  const double f =
      prestress_factor_at(4.0 * sigma_p_Pa / lambda_s * inv_E_per_Pa, sigma_p_Pa,
                          saturation_stress(lambda_s, E_Pa), maximum_stress(lambda_s, E_Pa));
  return f * lambda_s * m * m;
}
inline double magnetostriction(double m, double lambda_s, double sigma_p_Pa, double E_Pa) {
  return magnetostriction(m, lambda_s, sigma_p_Pa, E_Pa, 1.0 / E_Pa);
}

// Eq. (14): magnetostrictive force of one rod [N].  F = lambda E A.
inline double rod_force(double lambda, double E_Pa, double area_m2) {
  return lambda * E_Pa * area_m2;
}

}  // namespace gmasim::physics
