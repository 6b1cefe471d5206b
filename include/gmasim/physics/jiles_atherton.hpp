// Temperature-dependent Jiles-Atherton magnetisation: eq. (9) and eq. (10).
// SI units: fields and magnetisations in A/m, temperatures in kelvin unless named _C.
#pragma once

#include <cmath>

#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/series.hpp"

namespace gmasim::physics {

// Langevin function L(x) = coth x - 1/x and its derivative L'(x) = 1/x^2 - 1/sinh^2 x,
// from one exponential and one division (1/(x (1 - e)) gives 1/x and 1/(1 - e)); Taylor
// series for |x| < 0.1 (truncation below 1e-16 relative).
struct LangevinValue {
  double L, dL;
};
// The closed form for 0.1 <= |x| <= 40 from e = exp(-2|x|) (coth|x| = (1+e)/(1-e)).
inline LangevinValue langevin_pair_from_exp(double x, double e) {
  const double one_minus_e = 1.0 - e;
  const double q = 1.0 / (x * one_minus_e);
  const double inv_x = one_minus_e * q;
  const double inv_1me = x * q;  // 1 / (1 - e)
  const double coth_abs = (1.0 + e) * inv_1me;
  const double inv_sinh2 = 4.0 * e * inv_1me * inv_1me;
  return {(x > 0 ? coth_abs : -coth_abs) - inv_x, inv_x * inv_x - inv_sinh2};
}
inline LangevinValue langevin_series(double x) {
  const double x2 = x * x;
  return {x * (1.0 / 3.0 -
               x2 * (1.0 / 45.0 - x2 * (2.0 / 945.0 - x2 * (1.0 / 4725.0 - x2 * (2.0 / 93555.0))))),
          1.0 / 3.0 -
              x2 * (1.0 / 15.0 - x2 * (2.0 / 189.0 - x2 * (1.0 / 675.0 - x2 * (2.0 / 10395.0))))};
}
inline LangevinValue langevin_asymptote(double x) {
  const double inv_x = 1.0 / x;
  return {(x > 0 ? 1.0 : -1.0) - inv_x, inv_x * inv_x};
}
inline LangevinValue langevin_pair(double x) {
  const double ax = std::fabs(x);
  if (ax < 0.1) return langevin_series(x);
  if (ax > 40.0) return langevin_asymptote(x);
  return langevin_pair_from_exp(x, std::exp(-2.0 * ax));
}
// langevin_pair with its exponential exp(-2|x|) from an anchor nearby (p, physics::exp_near: a
// few units in the last place from langevin_pair; p moves where it is not near).
inline LangevinValue langevin_pair_near(double x, ExpPoint& p) {
  const double ax = std::fabs(x);
  if (ax < 0.1) return langevin_series(x);
  if (ax > 40.0) return langevin_asymptote(x);
  return langevin_pair_from_exp(x, exp_near(-2.0 * ax, p));
}
// The same with the solve's last value beside the anchor (exp_near(y, p, recent)).
inline LangevinValue langevin_pair_near(double x, ExpPoint& p, ExpPoint& recent) {
  const double ax = std::fabs(x);
  if (ax < 0.1) return langevin_series(x);
  if (ax > 40.0) return langevin_asymptote(x);
  return langevin_pair_from_exp(x, exp_near(-2.0 * ax, p, recent));
}
inline double langevin(double x) { return langevin_pair(x).L; }
inline double langevin_derivative(double x) { return langevin_pair(x).dL; }

// The four JA coefficients at one temperature (eq. 10 evaluated).
struct JaCoefficients {
  double a_A_per_m;  // shape coefficient a^T of the anhysteretic curve
  double alpha;      // domain-interaction coefficient alpha^T (dimensionless)
  double c;          // reversible coefficient c^T (dimensionless)
  double k_A_per_m;  // pinning coefficient k^T
};

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

// Eq. (9), second line, integrated over one step. dM_irr/dH_e = (M_an - M_irr)/(k delta)
// with delta = sign(dH_e) is, along the path length s = |H_e - H_e0|, the first-order
// relaxation  k dM_irr/ds = M_an - M_irr : a lag of M_irr behind M_an with "time
// constant" k. With M_an linear in s over the step (first-order hold) it has the same
// exact update as the eddy lag (magnetic.hpp), which is unconditionally stable however
// small k or large the field step. The guard of Jiles (1992), no change while
// (M_an - M_irr) delta <= 0, holds M_irr until M_an crosses it.
// Returns M_irr at the end of the step and, in dMirr_dHe1, its derivative with respect to
// the end field H_e1 given dMan1 = dM_an/dH_e there (for Newton's method in ja_step).
// inv_k = 1/k (JaMoveStart: one division per move, not two per evaluation). exp(-r) from the
// anchor `lag` where it is near, or from the solve's last value lag_recent (physics::exp_near;
// lag moves where neither is near).
inline double ja_irreversible_update(double Mirr0, double Man0, double Man1, double dMan1,
                                     double dHe, double inv_k, double& dMirr_dHe1, ExpPoint& lag,
                                     ExpPoint* lag_recent) {
  dMirr_dHe1 = 0.0;
  if (dHe == 0.0) return Mirr0;
  const double delta = dHe > 0.0 ? 1.0 : -1.0;
  const double d0 = (Man0 - Mirr0) * delta, d1 = (Man1 - Mirr0) * delta;
  if (d0 <= 0.0 && d1 <= 0.0) return Mirr0;  // pinned for the whole step
  double s = std::fabs(dHe), u0 = Man0;
  double ds_dHe1 = delta;  // d|He1 - He0| / dHe1
  if (d0 <= 0.0) {         // M_an crosses M_irr inside the step: relax over the remainder only
    const double frac = d1 / (d1 - d0);
    // d frac / dHe1 = -d0 (dd1/dHe1) / (d1 - d0)^2 with dd1/dHe1 = delta dMan1.
    ds_dHe1 = delta * frac - s * d0 * delta * dMan1 / ((d1 - d0) * (d1 - d0));
    s *= frac;
    u0 = Mirr0;
  }
  const double r = s * inv_k;
  // d/dHe1 through M_an1 (weight 1 - q) and through r = s/k (dq/dr = (E - q)/r): one
  // reciprocal of r for q and dq/dr (lag_weights_and_slope_from).
  const LagWeightsSlope w = lag_recent ? lag_weights_and_slope_near(r, lag, *lag_recent)
                                       : lag_weights_and_slope_near(r, lag);
  const double dq_dr = w.dq_dr;
  dMirr_dHe1 = (1.0 - w.q) * dMan1 + ds_dHe1 * inv_k * (-(Mirr0 - u0) * w.E - (Man1 - u0) * dq_dr);
  return Man1 + (Mirr0 - u0) * w.E - (Man1 - u0) * w.q;
}

// One step of eq. (9) from applied field H0 to H1. Solves for the end magnetisation M1
// the scalar equation  g(M1) = M1 - (1-c) M_irr1(M1) - c M_an(H1 + alpha M1) = 0  by
// Newton's method with its exact derivative (H_e depends on M through alpha), M_irr1 from
// ja_irreversible_update. M_guess is the starting point (e.g. linear extrapolation).
// The step's start enters through He0 = H0 + alpha M0 and Man0 = M_an(He0) (ja_move_start:
// fixed while a caller tries several end fields H1 from the same start). Returns M1 and M_irr1
// in M1_out and Mirr1_out; chi_e_out receives
//   chi_e = (1-c) dM_irr1/dH_e + c dM_an/dH_e  at H1,
// from which dM1/dH1 = chi_e / (1 - alpha chi_e) (the implicit-function derivative of g).
// At H1 == H0 nothing moves: M_irr1 = M_irr0, M1 = M0 and chi_e is the reversible c dM_an/dH_e.
struct JaMoveStart {
  double He0, Man0;
  double inv_a;  // 1 / a^T, for the move's evaluations (ja_evaluate)
  double inv_k;  // 1 / k^T, likewise (ja_irreversible_update)
};
inline JaMoveStart ja_move_start(double H0, double M0, double MsT_A_per_m,
                                 const JaCoefficients& p) {
  const double He0 = H0 + p.alpha * M0;
  const double inv_a = 1.0 / p.a_A_per_m;
  return {He0, MsT_A_per_m * langevin(He0 * inv_a), inv_a, 1.0 / p.k_A_per_m};
}
// ja_move_start with the Langevin function known at a nearby x_at = H_e / a (L and L' there,
// lv; the last evaluation of the law, where the last step ended): where |H_e0 / a - x_at| <=
// 1e-7, M_an(H_e0) = M_s^T (L(x_at) + L'(x_at) (x0 - x_at)), whose truncation (|L''| <= 0.5:
// below 3e-15 M_s^T) is far below eq. (9)'s tolerance; otherwise ja_move_start. x_at NaN:
// nothing known. (The consistent state commits its last iterate, so a step starts within
// about alpha 1e-12 M_s^T / a of it: one exponential less per rod and step.)
// inv_a = 1/a and inv_k = 1/k, divided once with the coefficients (RodConditions).
inline JaMoveStart ja_move_start_near(double H0, double M0, double MsT_A_per_m,
                                      const JaCoefficients& p, double inv_a, double inv_k,
                                      double x_at, const LangevinValue& lv) {
  const double He0 = H0 + p.alpha * M0;
  const double x0 = He0 * inv_a;
  if (std::fabs(x0 - x_at) <= 1e-7)
    return {He0, MsT_A_per_m * (lv.L + lv.dL * (x0 - x_at)), inv_a, inv_k};
  return {He0, MsT_A_per_m * langevin(x0), inv_a, inv_k};
}
// The anchors of an evaluation's exponentials (exp(-2|x|) of the Langevin function, exp(-r) of
// the lag; physics::exp_near), for the next evaluations nearby: a Newton solve's next iterate and
// the next step's (RodState::ja_exp).
struct JaExpPoints {
  ExpPoint langevin = kNoExpPoint, lag = kNoExpPoint;
};
// One evaluation of eq. (9) at the end field H1 and a magnetisation iterate M1 (inv_a = 1/a):
// M_irr1 from ja_irreversible_update, the magnetisation the law gives there,
//   F(M1) = (1-c) M_irr1 + c M_an(H1 + alpha M1),
// and chi_e = dF/dH_e. Eq. (9) holds where g = M1 - F(M1) = 0; its Newton step in M1 is
// -g / (1 - alpha chi_e) (ja_step_from iterates it; the consistent state's joint Newton solve
// takes one per circuit solve). `near`: the anchors of the exponentials (JaExpPoints; moved
// where they are not near); `recent` (or null): the exponentials' last values in the same solve,
// which the next iterate, much nearer, starts from (exp_near(y, a, recent)).
struct JaEvaluation {
  double Mirr1, M, chi_e;
  double x1;         // H_e1 / a, where the Langevin function was evaluated
  LangevinValue lv;  // L and L' at x1
};
// Always inlined (joint_trial, ja_step_from): out of line, GCC returned JaEvaluation through
// memory and saved registers, ~20 instructions per evaluation; the same arithmetic either way.
[[gnu::always_inline]] inline JaEvaluation ja_evaluate(const JaMoveStart& st, double H1, double M1,
                                                       double MsT_A_per_m, const JaCoefficients& p,
                                                       double Mirr0, double inv_a,
                                                       JaExpPoints& near, JaExpPoints* recent) {
  const double He1 = H1 + p.alpha * M1;
  const LangevinValue lv = recent ? langevin_pair_near(He1 * inv_a, near.langevin, recent->langevin)
                                  : langevin_pair_near(He1 * inv_a, near.langevin);
  const double Man1 = MsT_A_per_m * lv.L;
  const double dMan = MsT_A_per_m * inv_a * lv.dL;
  double dMirr = 0.0;
  const double Mirr1 = ja_irreversible_update(Mirr0, st.Man0, Man1, dMan, He1 - st.He0, st.inv_k,
                                              dMirr, near.lag, recent ? &recent->lag : nullptr);
  return {Mirr1, (1.0 - p.c) * Mirr1 + p.c * Man1, (1.0 - p.c) * dMirr + p.c * dMan, He1 * inv_a,
          lv};
}
inline JaEvaluation ja_evaluate(const JaMoveStart& st, double H1, double M1, double MsT_A_per_m,
                                const JaCoefficients& p, double Mirr0, double inv_a) {
  JaExpPoints none{};
  return ja_evaluate(st, H1, M1, MsT_A_per_m, p, Mirr0, inv_a, none, nullptr);
}
// The tolerance on g = M1 - F(M1) at which eq. (9) counts as solved [A/m]: 1e-12 M_s^T.
inline double ja_magnetisation_tolerance(double MsT_A_per_m) { return 1e-12 * MsT_A_per_m; }
// The consistent state's safeguard [A/m]: where a joint Newton iterate's residual |g| exceeds
// 1e-3 M_s^T, eq. (9) is solved at the trial field first (JilesAthertonLaw::joint_trial and
// its lanes). A jump of the current from rest to 6 A in one step still leaves |g| above it
// (tests/test_lanes.cpp, SafeguardSolvesEq9WhereTheScalarLawDoes); the quadratic first guess at
// 200 steps a period mostly does not. It was 1e-5 M_s^T: the joint solve converges from these
// guesses in a few more iterates, cheaper than the inner solve (measured in one gmasim_bench
// run: the 12-condition objective on the scalar step 3.95 -> 3.10 ms an evaluation, its lanes
// 1.94 -> 1.62 ms; 1e-2 and 1e-4 no better), and every result stays within the solve's tolerance
// (calibration_smoke's start RMS moved 4e-12 relative; docs/calibration.md).
inline double ja_safeguard_residual(double MsT_A_per_m) { return 1e-3 * MsT_A_per_m; }

inline void ja_step_from(double H0, const JaMoveStart& st, double H1, double MsT_A_per_m,
                         const JaCoefficients& p, double Mirr0, double M0, double M_guess,
                         double& Mirr1_out, double& M1_out, double& chi_e_out) {
  const double inv_a = 1.0 / p.a_A_per_m;
  if (H1 == H0) {
    const LangevinValue lv = langevin_pair((H0 + p.alpha * M0) * inv_a);
    Mirr1_out = Mirr0;
    M1_out = M0;
    chi_e_out = p.c * MsT_A_per_m * inv_a * lv.dL;
    return;
  }
  const double tol = ja_magnetisation_tolerance(MsT_A_per_m);
  double M1 = M_guess;
  for (int it = 0; it < 60; ++it) {
    const JaEvaluation e = ja_evaluate(st, H1, M1, MsT_A_per_m, p, Mirr0, inv_a);
    const double g = M1 - e.M;
    if (std::fabs(g) <= tol || it == 59) {
      Mirr1_out = e.Mirr1;
      M1_out = e.M;
      chi_e_out = e.chi_e;
      return;
    }
    double dg = 1.0 - p.alpha * e.chi_e;
    if (dg < 0.2) dg = 0.2;  // alpha > 0 (positive feedback): damp the Newton step
    M1 -= g / dg;
  }
}
// The slope dM/dH = chi_e / (1 - alpha chi_e) along a step (ja_step_from's chi_e).
inline double ja_slope(double chi_e, const JaCoefficients& p) {
  return chi_e / (1.0 - p.alpha * chi_e);
}

// The same slope with what the consistent state's Newton solve needs beside it, from one
// division: with d = 1 - alpha chi_e,
//   dM/dH = chi_e / d,   1/mu_r = 1/(1 + dM/dH) = d / (d + chi_e),   1/d,
// the last for the Newton step -g/d of eq. (9) in M (ja_evaluate), d held >= 0.2 as in
// ja_step_from (alpha > 0 is positive feedback).
struct JaSlopeTerms {
  double dM_dH, inv_mu_r, inv_dg;
};
inline JaSlopeTerms ja_slope_terms(double chi_e, const JaCoefficients& p) {
  const double d = 1.0 - p.alpha * chi_e, dc = d + chi_e;
  const double inv = 1.0 / (d * dc);
  return {chi_e * dc * inv, d * d * inv, d >= 0.2 ? dc * inv : 5.0};
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
