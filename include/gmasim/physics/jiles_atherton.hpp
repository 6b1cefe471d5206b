// Temperature-dependent Jiles-Atherton magnetisation: eq. (9) and eq. (10).
// SI units: fields and magnetisations in A/m, temperatures in kelvin unless named _C.
#pragma once

#include <cmath>

#include "gmasim/physics/laws.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/series.hpp"

namespace gmasim::physics {

// The Jiles-Atherton law itself, over the number type (the Langevin function, the irreversible
// update, the evaluation, the step and the joint trial), is gmasim/physics/laws-inl.h; these are
// its scalar conveniences.
inline double langevin(double x) { return langevin_pair(x).L; }
inline double langevin_derivative(double x) { return langevin_pair(x).dL; }

// Eq. (9), fourth line: anhysteretic magnetisation M_an = M_s^T [coth(He/a) - a/He].
inline double anhysteretic(double He_A_per_m, double MsT_A_per_m, double a_A_per_m) {
  return MsT_A_per_m * langevin(He_A_per_m / a_A_per_m);
}
inline double anhysteretic_slope(double He_A_per_m, double MsT_A_per_m, double a_A_per_m) {
  return MsT_A_per_m / a_A_per_m * langevin_derivative(He_A_per_m / a_A_per_m);
}

// Eq. (10): the printed temperature laws, as functions of the reduced temperature
// t = T/T_c (its scale, kelvin or celsius, is a model option: docs/model.md).
//   alpha^T = alpha0 e^{-(2/beta1) t} (1 - t)^{-beta1}
//   k^T     = k0     e^{-(1/beta2) t}
//   a^T     = a0     e^{-(1/beta3) t}
//   c^T     = c0     e^{-(2/beta1) t} (1 - t)^{-beta1}
inline double eq10_alpha_factor(double t, double beta1) {
  return std::exp(-2.0 / beta1 * t) * std::pow(1.0 - t, -beta1);
}
inline double eq10_k_factor(double t, double beta2) { return std::exp(-t / beta2); }
inline double eq10_a_factor(double t, double beta3) { return std::exp(-t / beta3); }
inline double eq10_c_factor(double t, double beta1) {
  return std::exp(-2.0 / beta1 * t) * std::pow(1.0 - t, -beta1);
}
// Alternative a^T law of mean-field theory (ref. 27's basis): a is proportional to the
// absolute temperature, a^T = a_ref T_K / T_ref_K. Offered as an option, see docs.
inline double mean_field_a_factor(double T_K, double Tref_K) { return T_K / Tref_K; }

// Eq. (9), lines 1, 3 and 5: total magnetisation M = M_irr + c (M_an(H + alpha M) - M_irr),
// implicit in M through H_e. Solved by Newton from the guess M_guess (a warm start).
// Converges when |c alpha dM_an/dHe| < 1, true for every physical parameter set.
inline double ja_total_magnetisation(double H_A_per_m, double Mirr_A_per_m, double M_guess,
                                     double MsT_A_per_m, const JaCoefficients& p) {
  double M = M_guess;
  for (int it = 0; it < 8; ++it) {
    const double He = H_A_per_m + p.alpha * M;
    const double x = He / p.a_A_per_m;
    const double Man = MsT_A_per_m * langevin(x);
    const double dMan = MsT_A_per_m / p.a_A_per_m * langevin_derivative(x);
    const double g = M - (1.0 - p.c) * Mirr_A_per_m - p.c * Man;
    const double dg = 1.0 - p.c * dMan * p.alpha;
    const double dM = g / dg;
    M -= dM;
    if (std::fabs(dM) <= 1e-13 * (std::fabs(M) + MsT_A_per_m * 1e-6)) break;
  }
  return M;
}

// Eq. (9), second line, as a slope (for explicit integrators such as the RK4 reference):
// dM_irr/dH_e = (M_an - M_irr)/(k delta), delta = sign of dH_e, and zero where
// (M_an - M_irr) delta < 0 (Jiles 1992). With chi_e = (1-c) dMirr/dHe + c dMan/dHe and
// dH_e = dH + alpha dM, the slope along the applied field is
//   dM_irr/dH = (dM_irr/dH_e) / (1 - alpha chi_e).
inline double ja_irreversible_slope(double H_A_per_m, double M_A_per_m, double Mirr_A_per_m,
                                    double delta, double MsT_A_per_m, const JaCoefficients& p) {
  const double He = H_A_per_m + p.alpha * M_A_per_m;
  const double x = He / p.a_A_per_m;
  const double Man = MsT_A_per_m * langevin(x);
  const double diff = Man - Mirr_A_per_m;
  const double dirr_dHe = diff * delta > 0.0 ? diff / (p.k_A_per_m * delta) : 0.0;
  const double dMan = MsT_A_per_m / p.a_A_per_m * langevin_derivative(x);
  const double chi_e = (1.0 - p.c) * dirr_dHe + p.c * dMan;
  return dirr_dHe / (1.0 - p.alpha * chi_e);
}

// ja_move_start_near without a nearby point: M_an(H_e0) by the Langevin function (1/a and 1/k
// divided here).
inline JaMoveStart ja_move_start(double H0, double M0, double MsT_A_per_m,
                                 const JaCoefficients& p) {
  const double He0 = H0 + p.alpha * M0;
  const double inv_a = 1.0 / p.a_A_per_m;
  return {He0, MsT_A_per_m * langevin(He0 * inv_a), inv_a, 1.0 / p.k_A_per_m};
}
// ja_step_from for one rod (every lane: where = true).
inline void ja_step_from(double H0, const JaMoveStart& st, double H1, double MsT_A_per_m,
                         const JaCoefficients& p, double Mirr0, double M0, double M_guess,
                         double& Mirr1_out, double& M1_out, double& chi_e_out) {
  ja_step_from(H0, st, H1, MsT_A_per_m, p, Mirr0, M0, M_guess, Mirr1_out, M1_out, chi_e_out, true);
}

// The slope dM/dH = chi_e / (1 - alpha chi_e) along a step (ja_step_from's chi_e).
inline double ja_slope(double chi_e, const JaCoefficients& p) {
  return chi_e / (1.0 - p.alpha * chi_e);
}

// One step of eq. (9) from H0 to H1 (ja_step_from from the start (H0, Mirr, M)).
// On entry M must be consistent with (H0, Mirr); on exit Mirr and M hold the values at H1.
// If dM_dH is given it receives the differential susceptibility along the step at H1
// (ja_slope; at H1 == H0 the reversible slope, M_irr pinned).
inline void ja_step(double H0, double H1, double MsT_A_per_m, const JaCoefficients& p, double& Mirr,
                    double& M, double M_guess, double* dM_dH = nullptr) {
  if (H1 == H0) {
    if (dM_dH) {
      double Mirr1 = 0.0, M1 = 0.0, chi_e = 0.0;
      ja_step_from(H0, {}, H1, MsT_A_per_m, p, Mirr, M, M_guess, Mirr1, M1, chi_e);
      *dM_dH = ja_slope(chi_e, p);
    }
    return;
  }
  double chi_e = 0.0;
  ja_step_from(H0, ja_move_start(H0, M, MsT_A_per_m, p), H1, MsT_A_per_m, p, Mirr, M, M_guess, Mirr,
               M, chi_e);
  if (dM_dH) *dM_dH = ja_slope(chi_e, p);
}
inline void ja_step(double H0, double H1, double MsT_A_per_m, const JaCoefficients& p, double& Mirr,
                    double& M) {
  ja_step(H0, H1, MsT_A_per_m, p, Mirr, M, M);
}

// ---------------------------------------------------------------------------------------
// Energy of eq. (9) (docs/model.md, "Energy ledgers"). With H_e = H + alpha M and
// M = (1 - c) M_irr + c M_an(H_e), the magnetic work on the material splits exactly into the
// change of a stored energy and a dissipation that is never negative:
//   mu0 H dM = d Phi + (1 - c) mu0 (H_e - H_an(M_irr)) dM_irr,
//   Phi = mu0 [ -alpha M^2/2 + c (H_e M_an(H_e) - G(H_e)) + (1 - c) Psi(M_irr) ],
// G(H_e) = int_0^He M_an = M_s a ln(sinh(He/a)/(He/a)) (the Langevin free energy), H_an the
// inverse of the anhysteretic curve and Psi(M) = H_an(M) M - G(H_an(M)) its Legendre dual.
// Where M_irr moves, (M_an(H_e) - M_irr) delta > 0 (eq. 9's guard), so H_e - H_an(M_irr) has
// the sign of dM_irr: the dissipation is >= 0 (the JA loop area, Jiles and Atherton 1986).
// ---------------------------------------------------------------------------------------

// ln(sinh x / x), even in x, without overflow or cancellation [-].
inline double log_sinh_over_x(double x) {
  const double ax = std::fabs(x);
  if (ax < 0.1) {
    const double x2 = x * x;
    return x2 * (1.0 / 6.0 - x2 * (1.0 / 180.0 - x2 * (1.0 / 2835.0 - x2 / 37800.0)));
  }
  // sinh x / x = e^x (1 - e^{-2x}) / (2x)
  return ax + std::log1p(-std::exp(-2.0 * ax)) - std::log(2.0 * ax);
}

// G(H_e) = int_0^He M_an(h) dh = M_s a ln(sinh(He/a)/(He/a))  [A^2/m^2].
inline double anhysteretic_coenergy(double He_A_per_m, double MsT_A_per_m, double a_A_per_m) {
  return MsT_A_per_m * a_A_per_m * log_sinh_over_x(He_A_per_m / a_A_per_m);
}

// The inverse of the Langevin function: x with L(x) = m, |m| < 1. Newton's method from
// `guess` (or, if it is not finite, from x = m (3 - m^2)/(1 - m^2), Cohen's approximant),
// converged to 1e-14 in L.
inline double inverse_langevin(double m, double guess = std::nan("")) {
  double x = std::isfinite(guess) ? guess : m * (3.0 - m * m) / (1.0 - m * m);
  for (int it = 0; it < 50; ++it) {
    const LangevinValue v = langevin_pair(x);
    const double r = v.L - m;
    if (std::fabs(r) <= 1e-14) break;
    double dx = r / v.dL;
    // keep the iterate on the side where L is defined and monotone (|L| < 1)
    if (std::fabs(dx) > 0.5 * (1.0 + std::fabs(x)))
      dx = (dx > 0 ? 0.5 : -0.5) * (1.0 + std::fabs(x));
    x -= dx;
  }
  return x;
}

// H_an(M): the field on the anhysteretic curve of eq. (9) where M_an = M  [A/m].
inline double anhysteretic_field(double M_A_per_m, double MsT_A_per_m, double a_A_per_m,
                                 double guess_A_per_m = std::nan("")) {
  return a_A_per_m * inverse_langevin(M_A_per_m / MsT_A_per_m, guess_A_per_m / a_A_per_m);
}

// Phi of the split above: the energy eq. (9) stores in the material per unit volume,
// beyond the field's mu0 H^2/2  [J/m^3]. Han_irr = anhysteretic_field(M_irr).
inline double ja_stored_energy_density(double H_A_per_m, double M_A_per_m, double Mirr_A_per_m,
                                       double Han_irr_A_per_m, double MsT_A_per_m,
                                       const JaCoefficients& p) {
  const double He = H_A_per_m + p.alpha * M_A_per_m;
  const double Man = anhysteretic(He, MsT_A_per_m, p.a_A_per_m);
  const double psi = Han_irr_A_per_m * Mirr_A_per_m -
                     anhysteretic_coenergy(Han_irr_A_per_m, MsT_A_per_m, p.a_A_per_m);
  return kMu0 * (-0.5 * p.alpha * M_A_per_m * M_A_per_m +
                 p.c * (He * Man - anhysteretic_coenergy(He, MsT_A_per_m, p.a_A_per_m)) +
                 (1.0 - p.c) * psi);
}

// The dissipation density of the split over one step of eq. (9) [J/m^3]. A step fixes only its
// ends (H0, M0) -> (H1, M1); between them H and M are taken linear in one path parameter s, so
// that H is linear in M and the material's work over the path, mu0 int H dM, is exactly the
// trapezoid mu0 (H0 + H1)/2 (M1 - M0) that the circuit's discrete update delivers. Along the
// path H_e = H + alpha M and (1 - c) M_irr = M - c M_an(H_e); the split holds on any path, and
//   D = (1 - c) mu0 int (H_e - H_an(M_irr)) dM_irr
// is integrated by 4-point Gauss-Legendre in s (the integrand is smooth on a step). The
// rate (1 - c) dM_irr/ds = dM - c M_an'(H_e) dH_e is formed without dividing by 1 - c.
inline double ja_step_dissipation(double H0, double M0, double H1, double M1, double MsT_A_per_m,
                                  const JaCoefficients& p) {
  constexpr double node[4] = {0.5 - 0.5 * 0.8611363115940526, 0.5 - 0.5 * 0.3399810435848563,
                              0.5 + 0.5 * 0.3399810435848563, 0.5 + 0.5 * 0.8611363115940526};
  constexpr double weight[4] = {0.5 * 0.3478548451374538, 0.5 * 0.6521451548225463,
                                0.5 * 0.6521451548225463, 0.5 * 0.3478548451374538};
  const double dH = H1 - H0, dM = M1 - M0;
  if (dH == 0.0 && dM == 0.0) return 0.0;
  constexpr double lim = 1.0 - 1e-12;  // |M_irr| < M_s (rounding near c = 1)
  double x_an = std::nan(""), sum = 0.0;
  for (int q = 0; q < 4; ++q) {
    const double H = H0 + node[q] * dH, M = M0 + node[q] * dM, He = H + p.alpha * M;
    const LangevinValue lv = langevin_pair(He / p.a_A_per_m);
    const double one_minus_c_Mirr = M - p.c * MsT_A_per_m * lv.L;
    const double one_minus_c_dMirr =
        dM - p.c * MsT_A_per_m / p.a_A_per_m * lv.dL * (dH + p.alpha * dM);
    double m_irr = one_minus_c_Mirr / ((1.0 - p.c) * MsT_A_per_m);
    m_irr = m_irr > lim ? lim : (m_irr < -lim ? -lim : m_irr);
    x_an = inverse_langevin(m_irr, x_an);
    sum += weight[q] * (He - p.a_A_per_m * x_an) * one_minus_c_dMirr;
  }
  return kMu0 * sum;
}

}  // namespace gmasim::physics
