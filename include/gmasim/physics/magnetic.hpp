// The paper's magnetic laws (section 3.1 and 3.2): eq. 1-8.
// Pure functions of scalars, SI units throughout (A/m, T, Pa, H/m, ohm*m, kelvin
// differences); each cites its equation in ../shared/paper/mctd-paper.txt.
#pragma once

#include <cmath>

#include "gmasim/physics/series.hpp"

namespace gmasim::physics {

inline constexpr double kMu0 = 1.25663706212e-6;  // vacuum permeability [H/m]
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;
inline constexpr double kZeroCelsiusInK = 273.15;

// Eq. (1): temperature-dependent bias MMF of the permanent magnets [A-turns].
//   F_pm^T = F_pm (1 + a1 (T - T0) + a2 (T - T0)^2)
inline double pm_mmf(double F_pm_At, double alpha_pm1_per_K, double alpha_pm2_per_K2, double dT_K) {
  return F_pm_At * (1.0 + alpha_pm1_per_K * dT_K + alpha_pm2_per_K2 * dT_K * dT_K);
}

// Eq. (2): reluctance of a magnetostrictive rod [1/H].  R = l / (mu A).
inline double rod_reluctance(double length_m, double mu_H_per_m, double area_m2) {
  return length_m / (mu_H_per_m * area_m2);
}

// Eq. (4): temperature-dependent saturation magnetisation [A/m].
//   M_s^T = M_s (1 - dT/(T_c - T_r))^x
inline double saturation_magnetisation(double Ms_A_per_m, double dT_K, double Tc_minus_Tr_K,
                                       double x) {
  return Ms_A_per_m * std::pow(1.0 - dT_K / Tc_minus_Tr_K, x);
}

// Eq. (5): relaxation factor k = (pi/2) chi_m / M_s^T  [m/A].
inline double relaxation_factor(double chi_m, double MsT_A_per_m) {
  return 0.5 * kPi * chi_m / MsT_A_per_m;
}

// Eq. (6): Lambda_0(sigma), the primitive of the domain-rotation strain lambda_0(sigma)
// [Pa, i.e. J/m^3]. sigma0 = sigma_lambda * artanh(1/3). Compression is negative in this
// form (Zheng/Zhou convention); see docs/model.md.
inline double sigma0_of(double sigma_lambda_Pa) { return sigma_lambda_Pa * std::atanh(1.0 / 3.0); }
inline double Lambda0(double sigma_Pa, double lambda_s, double sigma_lambda_Pa) {
  const double s = (sigma_Pa - sigma0_of(sigma_lambda_Pa)) / sigma_lambda_Pa;
  // ln((2 sqrt2 / 3) cosh s) computed without overflow for large |s|:
  // ln cosh s = |s| + log1p(exp(-2|s|)) - ln 2.
  const double as = std::fabs(s);
  const double ln_cosh = as + std::log1p(std::exp(-2.0 * as)) - std::log(2.0);
  const double ln_term = std::log(2.0 * std::sqrt(2.0) / 3.0) + ln_cosh;
  return 0.25 * lambda_s * sigma_Pa + 0.75 * lambda_s * sigma_lambda_Pa * ln_term;
}

// The stress part of the bracket of eq. (3) and of the denominator of eq. (13), in
// units of J/m^3:  S = 2 (lambda_s sigma - Lambda_0(sigma)) + 2 beta dT sigma.
// It does not depend on M, so Conditions precompute it.
inline double stress_energy_term(double sigma_Pa, double lambda_s, double Lambda0_Pa,
                                 double beta_per_K, double dT_K) {
  return 2.0 * (lambda_s * sigma_Pa - Lambda0_Pa) + 2.0 * beta_per_K * dT_K * sigma_Pa;
}

// Eq. (3): inverse differential susceptibility (the bracket before the -1 power):
//   1/chi = pi/(2 k M_s^T) sec^2(pi M / 2 M_s^T) - S / (mu0 (M_s^T)^2)
// With eq. (5), pi/(2 k M_s^T) = 1/chi_m (READING-NOTES), so
//   1/chi = sec^2(pi m / 2)/chi_m - S/(mu0 Ms^2),  m = M / M_s^T.
// Returns 1/chi; it must stay > 0 for a physical permeability.
inline double inverse_susceptibility(double m, double chi_m, double S_J_per_m3,
                                     double MsT_A_per_m) {
  const double c = std::cos(0.5 * kPi * m);
  return 1.0 / (chi_m * c * c) - S_J_per_m3 / (kMu0 * MsT_A_per_m * MsT_A_per_m);
}

// Eq. (3), consistent reading (docs/model.md, "Magnetic state"): eq. (3) is the
// differential permeability of the anhysteretic H(M) = (2 M_s/(pi chi_m)) tan(pi M/2M_s)
// - S M/(mu0 M_s^2). Its stress and temperature terms are therefore a field alpha_sigma M
// that adds to the JA effective field of eq. (9): H_e = H + (alpha^T + alpha_sigma) M, with
//   alpha_sigma = S / (mu0 (M_s^T)^2)     [-]
// (the magnetoelastic coupling of Jiles' H_sigma = (3 sigma/2 mu0) dlambda/dM has this form).
inline double magnetoelastic_coupling(double S_J_per_m3, double MsT_A_per_m) {
  return S_J_per_m3 / (kMu0 * MsT_A_per_m * MsT_A_per_m);
}

// Flux density of a magnetised material [T]:  B = mu0 (H + M).
inline double flux_density(double H_A_per_m, double M_A_per_m) {
  return kMu0 * (H_A_per_m + M_A_per_m);
}

// Eq. (3): magneto-thermo-elastic permeability mu_G^{M,T,sigma} [H/m].
//   mu = mu0 (1 + chi)
inline double permeability(double inverse_chi) { return kMu0 * (1.0 + 1.0 / inverse_chi); }

// Eq. (7), first line: the static (quasi-static) field in the rod from its flux [A/m].
//   H_c = phi / (k_f mu A)
inline double static_field(double phi_Wb, double k_f, double mu_H_per_m, double area_m2) {
  return phi_Wb / (k_f * mu_H_per_m * area_m2);
}

// Eq. (7), first line, consistent reading (docs/model.md, "The magnetic state"): the MMF across
// a rod branch that does not drop across the Terfenol-D drops across its joints (between its
// short rods, and against the magnetizers): air or epoxy gaps of total equivalent length g, a
// lossless, linear series reluctance
//   R_s = g / (mu0 A)      [1/H]
// so that U = l H_c + R_s phi. (The printed reading's k_f, which divides the field by 3.8-12.3,
// would need gaps of millimetres to centimetres: it compensated eq. (3)'s permeability in the
// printed circuit and has no place here.)
inline double joint_reluctance(double gap_m, double area_m2) { return gap_m / (kMu0 * area_m2); }

// A part of constant relative permeability mu_r as a fixed reluctance of the netlist (eq. 2's law
// R = l / (mu A) with mu = mu0 mu_r) [1/H]: [circuit.reluctance_geometry.<name>].
inline double fixed_reluctance(double length_m, double relative_permeability, double area_m2) {
  return length_m / (kMu0 * relative_permeability * area_m2);
}

// Eq. (7), second line: time constant of the first-order eddy-current lag [s].
//   H(s) = H_c(s) / (1 + tau s),  tau = mu (r1^2 - r2^2) / (4 k_j rho)
// (the second "k_f" of the printed eq. 7 is Table 4's k_j: READING-NOTES).
inline double eddy_time_constant(double mu_H_per_m, double r_outer_m, double r_inner_m, double k_j,
                                 double rho_ohm_m) {
  return mu_H_per_m * (r_outer_m * r_outer_m - r_inner_m * r_inner_m) / (4.0 * k_j * rho_ohm_m);
}

// Eq. (7)'s kappa by the classical eddy law (options.eddy_law = "classical"; not in the paper,
// docs/model.md "The eddy law"). A long tube of radii r2 < r1 and resistivity rho in a uniform
// axial dB/dt (flux in the bore neglected): Faraday gives E(r) = -(r^2 - r2^2)/(2 r) dB/dt, the
// azimuthal current J = E/rho, and Ampere dH/dr = -J, so the field inside lags the surface field
// by (dB/dt / rho) f(r), f(r) = (r1^2 - r^2)/4 - (r2^2/2) ln(r1/r). Its mean over the section:
//   kappa = [ (r1^2 - r2^2)/8 - r2^2/4 + r2^4 ln(r1/r2) / (2 (r1^2 - r2^2)) ] / rho   [s m/H]
// which is r1^2/(8 rho) for a solid rod (r2 = 0): the classical first-order eddy lag of a
// cylinder, tau = mu r^2/(8 rho) (derived here; tests/test_eddy_law.cpp integrates f(r)).
inline double classical_eddy_coefficient(double r_outer_m, double r_inner_m, double rho_ohm_m) {
  const double a2 = r_outer_m * r_outer_m, b2 = r_inner_m * r_inner_m;
  double k = 0.125 * (a2 - b2);
  // The three terms cancel for a thin wall t: about (r/t)^2 ulp are lost (6e-11 relative at
  // r/t = 100, tests/test_eddy_law.cpp); log1p keeps the logarithm exact.
  if (b2 > 0.0)
    k += -0.25 * b2 + b2 * b2 * std::log1p((r_outer_m - r_inner_m) / r_inner_m) / (2.0 * (a2 - b2));
  return k / rho_ohm_m;
}

// Eq. (7), consistent reading: the field the circuit applies to a rod, H_c = U/(k_f l), is
// the material's field H plus the eddy-current field, which opposes the change of flux:
//   H_c = H + kappa dB/dt,   kappa = (r1^2 - r2^2)/(4 k_j rho)   [s m/H]
// (kappa = eddy_time_constant(1, ...); for a linear material dB = mu dH this is eq. 7's
// H(s) = H_c(s)/(1 + tau s) with tau = mu kappa). Trapezoidal average over a step h:
//   (H_c0 + H_c1)/2 = (H0 + H1)/2 + kappa (B1 - B0)/h,
// given g = 2 kappa / h [A/(m T)]: eddy_static_field_trapezoid, written once over the number type
// in gmasim/physics/joint_newton-inl.h (the consistent state's solve and commit).

// Eq. (8): temperature-dependent resistivity of Terfenol-D [ohm m].
//   rho^T = rho0 + 2.5e-9 (T - T0)   (the slope is a model parameter, default 2.5e-9)
inline double resistivity(double rho0_ohm_m, double drho_dT_ohm_m_per_K, double dT_K) {
  return rho0_ohm_m + drho_dT_ohm_m_per_K * dT_K;
}

// exp(-r) and q(r) = (1 - exp(-r))/r with one exponential; q by its Taylor series for
// small r (truncation below 1e-16 relative), where 1 - exp(-r) would cancel.
struct LagWeights {
  double E, q;
};
inline LagWeights lag_weights(double r) {
  const double E = std::exp(-r);
  if (r < 1e-2) {
    const double q =
        1.0 - r * (1.0 / 2 - r * (1.0 / 6 - r * (1.0 / 24 - r * (1.0 / 120 - r * (1.0 / 720)))));
    return {E, q};
  }
  return {E, (1.0 - E) / r};
}

// Exact update of the first-order lag  tau dH/dt = u(t) - H  over one step h with u
// linear from u0 to u1 (first-order hold):
//   H1 = u1 + (H0 - u0) E - (u1 - u0) q,   E = exp(-h/tau), q = (1 - E) tau/h.
// Exact for ramps, unconditionally stable.
inline double first_order_lag_step(double H0, double u0, double u1, double h_s, double tau_s) {
  if (tau_s <= 0.0) return u1;
  const LagWeights w = lag_weights(h_s / tau_s);
  return u1 + (H0 - u0) * w.E - (u1 - u0) * w.q;
}

}  // namespace gmasim::physics
