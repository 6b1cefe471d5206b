// The Preisach law's distribution and the state of its hysterons (docs/model.md, "The Preisach
// law"): the coercive-field histogram and interaction spread, the extrema stack of the input's
// alternating dominant extrema, the search of the stack for the extremum a move continues from,
// and the commit of a move. Plain scalar code on one stack: the law's evaluation over the number
// type (the Everett function, the Newton solve: gmasim/physics/preisach_law-inl.h) reads a stack
// through preisach_base_at (gmasim/physics/laws.hpp; the lanes' src/lanes/number_lanes-inl.h),
// lane by lane. Header-only, allocation-free.
#pragma once

#include <array>
#include <cmath>
#include <limits>

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

// Commits a move to x1 whose end measure (mu, with its moments mc and mu_u) the law's solve
// found (preisach_law-inl.h): the stack is searched for the extremum the move continues from
// (preisach_base), then preisach_commit_point pushes and pops. The scalar law's commit_trial and
// the lanes' commit (each lane's own stack) both commit this way.
inline void preisach_commit_reached(PreisachHistory& h, double x1, double mu, double mc,
                                    double mu_u) {
  const PreisachBase b = preisach_base(h, x1);
  preisach_commit_point(h, x1, {mu, mc, mu_u, 0.0, b.base, b.push});
}

}  // namespace gmasim::physics
