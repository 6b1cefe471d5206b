// The Preisach model of hysteresis (docs/model.md, "The Preisach law"): a population of
// rectangular hysterons with up/down switching fields alpha >= beta, i.e. a coercive field
// h_c = (alpha - beta)/2 >= 0 and an interaction field h_u = (alpha + beta)/2, weighted by a
// distribution mu(h_c, h_u) = f_c(h_c) f_u(h_u) (Mayergoyz, "Mathematical Models of
// Hysteresis", 1991, ch. 1; Bertotti, "Hysteresis in Magnetism", 1998, ch. 9 and 13):
//   f_c  a log-normal in h_c (median 1, width sigma_c), as a histogram of kPreisachBins bins
//        between z = -3 and +3 standard deviations of ln h_c (piecewise-constant density);
//   f_u  a Gaussian in h_u (mean 0, standard deviation sigma_u).
// Fields are reduced, x = H_e / H_c^T: the law's coercivity law scales the whole distribution
// (docs/model.md). With this distribution the Everett function (the measure of a triangle of
// the Preisach plane) and its first moments are closed forms of the Gaussian CDF.
// The distribution and the extrema stack: gmasim/physics/preisach_history.hpp. The law's
// evaluation (Everett function, Newton solve, trial) is written once over the number type in
// gmasim/physics/preisach_law-inl.h; this header gives its double conveniences, the AC
// demagnetisation, the anhysteretic state and the energy. Header-only, allocation-free.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "gmasim/physics/jiles_atherton.hpp"
#include "gmasim/physics/laws.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/preisach_history.hpp"

namespace gmasim::physics {

// The distribution's numbers as the law's template reads them.
inline PreisachBins preisach_bins(const PreisachDistribution& d) {
  PreisachBins k{};
  k.s = d.sigma_u;
  for (int j = 0; j <= kPreisachBins; ++j) k.edge[j] = d.edge[static_cast<std::size_t>(j)];
  for (int j = 0; j < kPreisachBins; ++j) k.density[j] = d.density[static_cast<std::size_t>(j)];
  return k;
}

// The Everett function of the triangle T(a, b) (everett_bins; a may be +inf, b -inf).
inline Everett everett(const PreisachDistribution& d, double a, double b) {
  return everett_bins(preisach_bins(d), a, b);
}

// The up-switched measure (and its moments) at reduced input x1, reached monotonically from
// the history's x_now, without changing the history. mu' = d mu / d x1 along that move.
inline PreisachPoint preisach_point(const PreisachDistribution& d, const PreisachHistory& h,
                                    double x1) {
  const PreisachBase b = preisach_base(h, x1);
  const PreisachPointT<double> p =
      preisach_point_from(preisach_bins(d), b.xb, b.mub, b.mcb, b.mub_u, b.up, b.same, x1);
  return {p.mu, p.mc, p.mu_u, p.dmu_dx, b.base, b.push};
}

// Moves the history to x1 (preisach_commit_point at the point preisach_point computes).
inline void preisach_commit(const PreisachDistribution& d, PreisachHistory& h, double x1) {
  preisach_commit_point(h, x1, preisach_point(d, h, x1));
}

// Positive then negative saturation (the two sentinels), then an AC demagnetisation about
// x_center: reversals at x_center +/- A r^k from A = the distribution's reach down to the
// smallest coercive field (below which nothing switches), ending at x_center. Each reversal
// takes one stack entry: ln(reach / edge_0) / ln(1/r) of them must fit kPreisachCapacity.
inline void preisach_ac_demagnetise(const PreisachDistribution& d, PreisachHistory& h,
                                    double x_center, double ratio) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const Everett all = everett(d, inf, -inf);
  h = PreisachHistory{};
  h.x[0] = inf;
  h.mu[0] = 1.0;
  h.mc[0] = all.Ec;
  h.mu_u[0] = all.Eu;
  h.x[1] = -inf;
  h.n = 2;
  h.x_now = -inf;
  const double reach = d.edge[kPreisachBins] + 6.0 * d.sigma_u;
  double sign = 1.0;
  for (double A = reach; A > d.edge[0]; A *= ratio, sign = -sign)
    preisach_commit(d, h, x_center + sign * A);
  preisach_commit(d, h, x_center);
  h.last_dmc = 0.0;
}

// make_state's demagnetised rod: reversal ratio 0.8.
inline void preisach_demagnetise(const PreisachDistribution& d, PreisachHistory& h,
                                 double x_center) {
  preisach_ac_demagnetise(d, h, x_center, 0.8);
}

// The anhysteretic state at a DC (reduced, effective) field x: an AC demagnetisation about x
// whose amplitude decays slowly, with the finest reversal ratio whose reversals fit the stack
// (kPreisachCapacity - 8 of them, leaving room for the small-signal reversals about it).
inline double preisach_anhysteretic_ratio(const PreisachDistribution& d) {
  const double reach = d.edge[kPreisachBins] + 6.0 * d.sigma_u;
  return std::pow(d.edge[0] / reach, 1.0 / (kPreisachCapacity - 8));
}
inline void preisach_anhysteretic_history(const PreisachDistribution& d, PreisachHistory& h,
                                          double x) {
  preisach_ac_demagnetise(d, h, x, preisach_anhysteretic_ratio(d));
}

// Its closed form, the limit of ever slower decay (docs/model.md, "The Preisach law"): the
// staircase of the reversals x +/- A_k tends to the line alpha + beta = 2 x of the Preisach
// plane, i.e. h_u = x, below which every hysteron is up. With mu(h_c, h_u) = f_c(h_c) f_u(h_u)
// the up-switched measure is then the interaction fields' CDF, whatever f_c:
//   mu_an(x) = F_u(x) = Phi(x / sigma_u),  d mu_an / dx = f_u(x).
inline double preisach_anhysteretic_mu(const PreisachDistribution& d, double x) {
  return 0.5 * std::erfc(-x / (d.sigma_u * std::sqrt(2.0)));
}

// ---------------------------------------------------------------------------------------
// The law of a rod (docs/model.md, "The Preisach law"): the hysterons of the irreversible
// part, a reversible Langevin part, and a mean field (Della Torre's moving model):
//   M = M_s^T [ (1 - c) (2 mu(x) - 1) + c L(H_e / a) ],  H_e = H + alpha M,  x = H_e / H_c^T.
// ---------------------------------------------------------------------------------------
struct PreisachCoefficients {  // at one temperature
  double Hc_A_per_m = 1.0;     // coercivity law H_c^T: the unit of the reduced fields
  double c = 0.0;              // reversible fraction
  double a_A_per_m = 1.0;      // shape of the reversible Langevin part a^T
  double alpha = 0.0;          // mean-field coupling (plus eq. 3's stress terms, consistent)
  PreisachDistribution dist;   // the hysterons, in reduced fields
};

// The law's constants at one temperature as its template reads them (inv_a = 1/a and inv_hc =
// 1/H_c as the lanes pack them).
inline PreisachConstants preisach_constants(double MsT_A_per_m, const PreisachCoefficients& p) {
  return {MsT_A_per_m,          p.c, p.alpha, p.a_A_per_m, 1.0 / p.a_A_per_m, 1.0 / p.Hc_A_per_m,
          preisach_bins(p.dist)};
}

// The end magnetisation of a move to field H1 from the history h (not committed): the law's
// Newton solve (preisach_solve) from M_guess. dM_dH (if given) receives chi_e / (1 - alpha
// chi_e); x1 (if given) the reduced input the move ends at; point (if given) the up-switched
// measure there, which preisach_commit_point commits without evaluating the distribution again.
inline double preisach_magnetisation(double H1, double MsT_A_per_m, const PreisachCoefficients& p,
                                     const PreisachHistory& h, double M_guess, double* dM_dH,
                                     double* x1, PreisachPoint* point = nullptr) {
  const PreisachSolveT<double> s =
      preisach_solve(true, preisach_constants(MsT_A_per_m, p), &h, H1, M_guess);
  if (dM_dH) *dM_dH = s.chi_e / (1.0 - p.alpha * s.chi_e);
  if (x1) *x1 = s.x1;
  if (point) {
    const PreisachBase b = preisach_base(h, s.x1);
    *point = {s.mu, s.mc, s.mu_u, 0.0, b.base, b.push};
  }
  return s.M;
}

// The slope at a reversal (preisach_reversible_slope): the reversible part with the mean field.
inline double preisach_reversible_susceptibility(double H, double M, double MsT_A_per_m,
                                                 const PreisachCoefficients& p) {
  return preisach_reversible_slope(preisach_constants(MsT_A_per_m, p), H, M);
}

// Energy (docs/model.md, "Energy ledgers"): a hysteron of weight w switching up at H_e = alpha'
// takes mu0 M_s 2 w alpha' = mu0 M_s 2 w (h_u + h_c): the h_u part is stored, the h_c part
// dissipated (either way). With the mean field and the reversible part as for eq. (9):
//   Phi = mu0 [ -alpha M^2/2 + c (H_e M_an - G(H_e)) ] + (1 - c) 2 mu0 M_s H_c mu_u,
//   D   = (1 - c) 2 mu0 M_s H_c |d mc|   per monotone move  [J/m^3].
inline double preisach_stored_energy_density(double H, double M, double MsT_A_per_m,
                                             const PreisachCoefficients& p,
                                             const PreisachHistory& h) {
  const double He = H + p.alpha * M;
  const double Man = anhysteretic(He, MsT_A_per_m, p.a_A_per_m);
  return kMu0 * (-0.5 * p.alpha * M * M +
                 p.c * (He * Man - anhysteretic_coenergy(He, MsT_A_per_m, p.a_A_per_m)) +
                 (1.0 - p.c) * 2.0 * MsT_A_per_m * p.Hc_A_per_m * h.mu_u_now);
}
inline double preisach_last_dissipation(double MsT_A_per_m, const PreisachCoefficients& p,
                                        const PreisachHistory& h) {
  return (1.0 - p.c) * 2.0 * kMu0 * MsT_A_per_m * p.Hc_A_per_m * h.last_dmc;
}

// The anhysteretic magnetisation of a rod at field H with the mean field (the closed form):
//   M = M_s^T [(1 - c)(2 mu_an(x) - 1) + c L(H_e / a)],  x = H_e / H_c,  H_e = H + alpha M,
// by Newton from M_guess (as preisach_magnetisation). dM_dH (if given): its slope.
inline double preisach_anhysteretic_magnetisation(double H, double MsT_A_per_m,
                                                  const PreisachCoefficients& p, double M_guess,
                                                  double* dM_dH = nullptr) {
  const double s = p.dist.sigma_u;
  double M = M_guess;
  for (int it = 0; it < 60; ++it) {
    const double He = H + p.alpha * M, x = He / p.Hc_A_per_m;
    const LangevinValue lv = langevin_pair(He / p.a_A_per_m);
    const double f = std::exp(-0.5 * (x / s) * (x / s)) / (s * std::sqrt(2.0 * kPi));
    const double Mnew =
        MsT_A_per_m *
        ((1.0 - p.c) * (2.0 * preisach_anhysteretic_mu(p.dist, x) - 1.0) + p.c * lv.L);
    const double chi_e =
        MsT_A_per_m * ((1.0 - p.c) * 2.0 * f / p.Hc_A_per_m + p.c * lv.dL / p.a_A_per_m);
    const double g = M - Mnew;
    if (std::fabs(g) <= 1e-12 * MsT_A_per_m || it == 59) {
      if (dM_dH) *dM_dH = chi_e / (1.0 - p.alpha * chi_e);
      return Mnew;
    }
    M -= g / std::max(1.0 - p.alpha * chi_e, 0.2);
  }
  return M;
}

// The rod put in the AC-demagnetised state at field H (the FRF's anhysteretic bias): the
// history of preisach_anhysteretic_history about x = (H + alpha M)/H_c, with M the law's
// magnetisation of that history at x (the mean field closes the loop; Newton with the
// closed form's slope, which the staircase follows to within its steps). Returns M.
inline double preisach_hold_anhysteretic(double H, double MsT_A_per_m,
                                         const PreisachCoefficients& p, PreisachHistory& h,
                                         double M_guess) {
  double dM_dH = 0.0;
  (void)preisach_anhysteretic_magnetisation(H, MsT_A_per_m, p, M_guess, &dM_dH);
  const double chi_e = dM_dH / (1.0 + p.alpha * dM_dH);  // the slope in H_e
  double M = M_guess;
  for (int it = 0; it < 60; ++it) {
    const double He = H + p.alpha * M;
    preisach_anhysteretic_history(p.dist, h, He / p.Hc_A_per_m);
    const double Mnew =
        MsT_A_per_m * ((1.0 - p.c) * (2.0 * h.mu_now - 1.0) + p.c * langevin(He / p.a_A_per_m));
    const double g = M - Mnew;
    if (std::fabs(g) <= 1e-12 * MsT_A_per_m) return Mnew;
    M -= g / std::max(1.0 - p.alpha * chi_e, 0.2);
  }
  return M;
}

}  // namespace gmasim::physics
