// Prestressed magnetostriction, the Delta-E effect and the rod force: eq. (11)-(14).
// SI units: stresses and moduli in Pa, magnetisation as the reduced m = M / M_s^T.
#pragma once

#include <cmath>

#include "gmasim/physics/laws.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim::physics {

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

inline double delta_e_modulus(double m, const DeltaETerms& d) {
  return 1.0 / delta_e_compliance(m, d);
}

inline double tanh_absolute(double u) { return tanh_from_exp(u, std::exp(-2.0 * std::fabs(u))); }
inline double prestress_factor_at(double two_sp_over_ss, double sigma_p_Pa, double sigma_s_Pa,
                                  double sigma_max_Pa) {
  return prestress_factor_from_tanh(tanh_absolute(two_sp_over_ss), sigma_p_Pa, sigma_s_Pa,
                                    sigma_max_Pa);
}
inline double prestress_factor(double sigma_p_Pa, double sigma_s_Pa, double sigma_max_Pa) {
  return prestress_factor_at(2.0 * sigma_p_Pa / sigma_s_Pa, sigma_p_Pa, sigma_s_Pa, sigma_max_Pa);
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

}  // namespace gmasim::physics
