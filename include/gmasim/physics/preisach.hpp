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
// Header-only, allocation-free.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "gmasim/physics/jiles_atherton.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim::physics {

inline constexpr int kPreisachBins = 8;
// Entries of the extrema stack (two of them are the saturation sentinels).
inline constexpr int kPreisachCapacity = 64;

// The distribution in reduced units (one rod at one temperature).
struct PreisachDistribution {
  double sigma_u = 0.5;                          // std of h_u / H_c^T
  std::array<double, kPreisachBins + 1> edge{};  // bin edges of h_c / H_c^T
  std::array<double, kPreisachBins> density{};   // f_c on each bin (integrates to 1)
};

// The log-normal histogram of width sigma_c (edges exp(sigma_c z_j), z_j = -3 + 6j/K, each
// bin weighted by its normal probability, renormalised to 1) and the interaction spread.
inline PreisachDistribution preisach_distribution(double sigma_c, double sigma_u) {
  PreisachDistribution d;
  d.sigma_u = sigma_u;
  auto Phi = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
  const double total = Phi(3.0) - Phi(-3.0);
  for (int j = 0; j <= kPreisachBins; ++j)
    d.edge[j] = std::exp(sigma_c * (-3.0 + 6.0 * j / kPreisachBins));
  for (int j = 0; j < kPreisachBins; ++j) {
    const double z0 = -3.0 + 6.0 * j / kPreisachBins, z1 = -3.0 + 6.0 * (j + 1) / kPreisachBins;
    d.density[j] = (Phi(z1) - Phi(z0)) / total / (d.edge[j + 1] - d.edge[j]);
  }
  return d;
}

// The Gaussian f_u of standard deviation s, its CDF F, A = int F and Y = int y F(y) dy.
struct GaussTerms {
  double F, f, A, Y;
};
inline GaussTerms gauss_terms(double y, double s) {
  const double F = 0.5 * std::erfc(-y / (s * std::sqrt(2.0)));
  const double f = std::exp(-0.5 * (y / s) * (y / s)) / (s * std::sqrt(2.0 * kPi));
  const double A = y * F + s * s * f;
  const double B = 0.5 * (y * y + s * s) * F + 0.5 * y * s * s * f;  // int A
  return {F, f, A, y * A - B};
}

// The triangle T(a, b) = {b <= beta <= alpha <= a} of the Preisach plane: its measure E (the
// Everett function), its moments in h_c and h_u, and dE/da, dE/db. a may be +inf, b -inf.
struct Everett {
  double E = 0, Ec = 0, Eu = 0, dE_da = 0, dE_db = 0;
};

// One side of the triangle: the integrals over h in [p, q] of F(a - h) (side a) or F(b + h)
// (side b), of h times it, and of the density f there, from the Gaussian terms at the two ends
// (gp at p, gq at q: gauss_terms(a - p) and gauss_terms(a - q) on side a, gauss_terms(b + p)
// and gauss_terms(b + q) on side b).
struct SideIntegrals {
  double I0 = 0, I1 = 0, J = 0;
};
inline SideIntegrals side_a(double a, const GaussTerms& gp, const GaussTerms& gq) {
  return {gp.A - gq.A, a * (gp.A - gq.A) - (gp.Y - gq.Y), gp.F - gq.F};
}
inline SideIntegrals side_b(double b, const GaussTerms& gp, const GaussTerms& gq) {
  return {gq.A - gp.A, (gq.Y - gp.Y) - b * (gq.A - gp.A), gq.F - gp.F};
}

// E(a, b) = int_0^D f_c(h) [F(a - h) - F(b + h)] dh, D = (a - b)/2; Ec with h f_c(h) in place
// of f_c; Eu = int_0^D f_c(h) s^2 [f(b + h) - f(a - h)] dh (int u f(u) du = -s^2 f(u)).
// The upper limit D (where a - h = b + h) adds nothing to the derivatives. A bin's Gaussian terms
// at its upper edge are the next bin's at its lower edge, so each edge is evaluated once (as the
// lanes do, src/lanes/preisach_lanes-inl.h); a = +inf makes side a {q - p, (q^2 - p^2)/2, 0},
// b = -inf side b nothing.
inline Everett everett(const PreisachDistribution& d, double a, double b) {
  Everett e;
  if (!(a > b)) return e;
  const bool a_inf = std::isinf(a), b_inf = std::isinf(b);
  const double D = (a_inf || b_inf) ? std::numeric_limits<double>::infinity() : 0.5 * (a - b);
  const double s = d.sigma_u;
  GaussTerms ga_p{}, gb_p{}, ga_q{}, gb_q{};
  if (!a_inf) ga_p = gauss_terms(a - d.edge[0], s);
  if (!b_inf) gb_p = gauss_terms(b + d.edge[0], s);
  for (int j = 0; j < kPreisachBins && d.edge[j] < D; ++j) {
    const double p = d.edge[j], q = std::min(d.edge[j + 1], D), w = d.density[j];
    SideIntegrals A{q - p, 0.5 * (q * q - p * p), 0.0}, B{};
    if (!a_inf) {
      ga_q = gauss_terms(a - q, s);
      A = side_a(a, ga_p, ga_q);
      ga_p = ga_q;
    }
    if (!b_inf) {
      gb_q = gauss_terms(b + q, s);
      B = side_b(b, gb_p, gb_q);
      gb_p = gb_q;
    }
    e.E += w * (A.I0 - B.I0);
    e.Ec += w * (A.I1 - B.I1);
    e.Eu += w * s * s * (B.J - A.J);
    e.dE_da += w * A.J;
    e.dE_db -= w * B.J;
  }
  return e;
}

// The state of the hysterons: the staircase of the Preisach plane as the stack of the input's
// alternating dominant extrema (Mayergoyz 1991, ch. 1.2), oldest first. Entry 0 is +inf (a
// maximum: positive saturation), entry 1 is -inf (a minimum: negative saturation); entries
// alternate max/min, so entry k is a maximum for even k. At each extremum it keeps the
// up-switched measure mu (M_P / M_s = 2 mu - 1) and the moments of the up-switched set in h_c
// and h_u. The input moves from the last extremum toward x_now (rising if that is a minimum).
// Fixed capacity: no allocation. Wiping-out removes a pair whenever the input passes the
// extremum before the last one, so a bounded input keeps the stack bounded; a reversal that
// finds it full forgets the innermost pair first (docs/model.md, "The Preisach law").
struct PreisachHistory {
  std::array<double, kPreisachCapacity> x{}, mu{}, mc{}, mu_u{};
  int n = 0;  // entries in use (0: not initialised)
  double x_now = 0, mu_now = 0, mc_now = 0, mu_u_now = 0;
  long forgotten = 0;   // reversals that found the stack full
  double last_dmc = 0;  // |change of the h_c moment| over the last committed move
};

// The up-switched measure (and its moments) at reduced input x1, reached monotonically from
// the history's x_now, without changing the history. mu' = d mu / d x1 along that move.
struct PreisachPoint {
  double mu = 0, mc = 0, mu_u = 0, dmu_dx = 0;
  int base = 0;       // the extremum the move continues from (index, or n for x_now itself)
  bool push = false;  // the move reverses: x_now becomes an extremum
};

// Where a move to x1 continues from (preisach_point's search of the stack, without the Everett
// function): the base extremum (index, or n for x_now), its input and up-switched measure and
// moments, the direction, and whether the move reverses. same: x1 == x_now (nothing moves).
struct PreisachBase {
  double xb = 0, mub = 0, mcb = 0, mub_u = 0;
  int base = 0;
  bool up = false, push = false, same = false;
};
inline PreisachBase preisach_base(const PreisachHistory& h, double x1) {
  PreisachBase r;
  if (x1 == h.x_now) {
    r = {h.x_now, h.mu_now, h.mc_now, h.mu_u_now, h.n, false, false, true};
    return r;
  }
  const bool rising_now = (h.n - 1) % 2 == 1;  // the last entry is a minimum
  r.up = x1 > h.x_now;
  r.push = r.up != rising_now;
  int len = h.n + (r.push ? 1 : 0);
  auto xs = [&](int k) { return k == h.n ? h.x_now : h.x[k]; };
  // Wiping-out: passing the extremum before the base removes the base and that extremum.
  while (len >= 3 && (r.up ? x1 >= xs(len - 2) : x1 <= xs(len - 2))) len -= 2;
  r.base = len - 1;
  r.xb = xs(r.base);
  r.mub = r.base == h.n ? h.mu_now : h.mu[r.base];
  r.mcb = r.base == h.n ? h.mc_now : h.mc[r.base];
  r.mub_u = r.base == h.n ? h.mu_u_now : h.mu_u[r.base];
  return r;
}

inline PreisachPoint preisach_point(const PreisachDistribution& d, const PreisachHistory& h,
                                    double x1) {
  PreisachPoint r;
  const PreisachBase b = preisach_base(h, x1);
  if (b.same) {
    r = {h.mu_now, h.mc_now, h.mu_u_now, 0.0, h.n, false};
    return r;
  }
  r.push = b.push;
  r.base = b.base;
  if (b.up) {  // the triangle T(x1, xb) switches up
    const Everett e = everett(d, x1, b.xb);
    r.mu = b.mub + e.E;
    r.mc = b.mcb + e.Ec;
    r.mu_u = b.mub_u + e.Eu;
    r.dmu_dx = e.dE_da;
  } else {  // the triangle T(xb, x1) switches down
    const Everett e = everett(d, b.xb, x1);
    r.mu = b.mub - e.E;
    r.mc = b.mcb - e.Ec;
    r.mu_u = b.mub_u - e.Eu;
    r.dmu_dx = -e.dE_db;
  }
  return r;
}

// Moves the history to x1, given the point p = preisach_point(d, h, x1) (its mu, mc, mu_u and
// base): pushes x_now if the move reverses (forgetting the innermost pair first if the stack
// is full), pops what the move wiped out, and records the change of the h_c moment (the
// switching loss, physics below).
inline void preisach_commit_point(PreisachHistory& h, double x1, const PreisachPoint& p) {
  h.last_dmc = std::fabs(p.mc - h.mc_now);
  if (x1 == h.x_now) return;
  if (p.base == h.n) {  // the move reverses at x_now and wipes nothing: x_now is an extremum
    if (h.n == kPreisachCapacity) {  // full: forget the innermost pair (not the sentinels)
      h.n -= 2;
      ++h.forgotten;
    }
    h.x[h.n] = h.x_now;
    h.mu[h.n] = h.mu_now;
    h.mc[h.n] = h.mc_now;
    h.mu_u[h.n] = h.mu_u_now;
    ++h.n;
  } else {
    h.n = p.base + 1;  // the extrema the move passed are wiped out
  }
  h.x_now = x1;
  h.mu_now = p.mu;
  h.mc_now = p.mc;
  h.mu_u_now = p.mu_u;
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

// The end magnetisation of a move to field H1 from the history h (not committed): Newton on
//   g(M) = M - M_s^T [(1 - c)(2 mu(x) - 1) + c L(H_e/a)] = 0 with its exact derivative
// (H_e and x depend on M through alpha), from M_guess. dM_dH (if given) receives
// chi_e / (1 - alpha chi_e), chi_e = M_s [(1 - c) 2 mu'(x) / H_c + c L'(H_e/a) / a]; x1 (if
// given) the reduced input the move ends at; point (if given) the up-switched measure there
// (preisach_point at x1), which preisach_commit_point commits without evaluating the
// distribution again.
inline double preisach_magnetisation(double H1, double MsT_A_per_m, const PreisachCoefficients& p,
                                     const PreisachHistory& h, double M_guess, double* dM_dH,
                                     double* x1, PreisachPoint* point = nullptr) {
  const double inv_a = 1.0 / p.a_A_per_m, inv_hc = 1.0 / p.Hc_A_per_m;
  const double tol = 1e-12 * MsT_A_per_m;
  double M = M_guess;
  for (int it = 0; it < 60; ++it) {
    const double He = H1 + p.alpha * M;
    const double x = He * inv_hc;
    const PreisachPoint pt = preisach_point(p.dist, h, x);
    const LangevinValue lv = langevin_pair(He * inv_a);
    const double Mnew = MsT_A_per_m * ((1.0 - p.c) * (2.0 * pt.mu - 1.0) + p.c * lv.L);
    const double chi_e =
        MsT_A_per_m * ((1.0 - p.c) * 2.0 * pt.dmu_dx * inv_hc + p.c * lv.dL * inv_a);
    const double g = M - Mnew;
    if (std::fabs(g) <= tol || it == 59) {
      if (dM_dH) *dM_dH = chi_e / (1.0 - p.alpha * chi_e);
      if (x1) *x1 = x;
      if (point) *point = pt;
      return Mnew;
    }
    double dg = 1.0 - p.alpha * chi_e;
    if (dg < 0.2) dg = 0.2;  // alpha > 0 (positive feedback): damp the Newton step
    M -= g / dg;
  }
  return M;
}

// The slope at a reversal (the hysterons' part has zero slope there, E ~ (a - b)^2): the
// reversible part with the mean field, c M_s L'/a / (1 - alpha c M_s L'/a).
inline double preisach_reversible_susceptibility(double H, double M, double MsT_A_per_m,
                                                 const PreisachCoefficients& p) {
  const double He = H + p.alpha * M;
  const double chi_e = p.c * MsT_A_per_m / p.a_A_per_m * langevin_derivative(He / p.a_A_per_m);
  return chi_e / (1.0 - p.alpha * chi_e);
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
