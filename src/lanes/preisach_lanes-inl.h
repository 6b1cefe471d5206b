// The Preisach law (gmasim/magnetisation/preisach.hpp, physics/preisach.hpp) over SIMD lanes: the
// magnetisation-law seam's second lane entry (docs/lanes.md, "Preisach lanes"). Each lane's
// extrema stack is its own (their depths differ): the search of the stack for the extremum a move
// continues from (physics::preisach_base) and the commit run lane by lane on the lane's
// PreisachHistory; the Everett function (8 bins, each side's Gaussian terms: an erfc whose
// exp(-z^2) the density shares) and the law's Newton solve run over the lanes, masked per lane,
// operation for operation physics::everett and physics::preisach_magnetisation otherwise. The
// vector erfc is Cody's rational Chebyshev approximation (erfc_cody). Included once per target by
// src/lanes/step_lanes.cpp (hwy/foreach_target.h); it includes the kernel (step_kernel-inl.h).
#if defined(GMASIM_LANES_PREISACH_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef GMASIM_LANES_PREISACH_INL_H_
#undef GMASIM_LANES_PREISACH_INL_H_
#else
#define GMASIM_LANES_PREISACH_INL_H_
#endif

#include <cmath>

#include "gmasim/physics/preisach.hpp"
#include "hwy/contrib/math/math-inl.h"
#include "hwy/highway.h"
#include "lanes/lane_data.hpp"
#include "lanes/step_kernel-inl.h"

HWY_BEFORE_NAMESPACE();
namespace gmasim::lanes::HWY_NAMESPACE {

// erfc(x) after W. J. Cody, "Rational Chebyshev approximations for the error function", Math.
// Comp. 23 (1969) 631-637 (the double-precision coefficients of his specfun routine CALERF,
// netlib): |x| <= 0.46875: 1 - x R1(x^2); 0.46875 < |x| <= 4: exp(-x^2) R2(|x|); |x| > 4:
// exp(-x^2) (1/sqrt(pi) - R3(1/x^2) / x^2) / |x|; exp(-x^2) as exp(-t^2) exp(-(|x| - t)(|x| + t))
// with t = |x| truncated to 1/16 (no rounding of x^2 enters the exponent); 0 beyond |x| =
// 26.543 (below the smallest double); erfc(-|x|) = 2 - erfc(|x|). Against glibc's erfc at 4e6
// random arguments in [-10, 27] (a standalone check of this function, SSE4): at most 4.8 units in
// the last place (1.1e-15 relative). gauss receives exp(-x^2) (the product above; 0 beyond 26.543),
// which the Gaussian density takes. Each branch is evaluated only where a lane needs it.
template <class D>
HWY_INLINE V<D> erfc_cody(D d, V<D> x, V<D>& gauss) {
  static constexpr double a[5] = {3.16112374387056560e00, 1.13864154151050156e02,
                                  3.77485237685302021e02, 3.20937758913846947e03,
                                  1.85777706184603153e-1};
  static constexpr double b[4] = {2.36012909523441209e01, 2.44024637934444173e02,
                                  1.28261652607737228e03, 2.84423683343917062e03};
  static constexpr double c[9] = {
      5.64188496988670089e-1, 8.88314979438837594e00, 6.61191906371416295e01,
      2.98635138197400131e02, 8.81952221241769090e02, 1.71204761263407058e03,
      2.05107837782607147e03, 1.23033935479799725e03, 2.15311535474403846e-8};
  static constexpr double dd[8] = {1.57449261107098347e01, 1.17693950891312499e02,
                                   5.37181101862009858e02, 1.62138957456669019e03,
                                   3.29079923573345963e03, 4.36261909014324716e03,
                                   3.43936767414372164e03, 1.23033935480374942e03};
  static constexpr double p[6] = {3.05326634961232344e-1, 3.60344899949804439e-1,
                                  1.25781726111229246e-1, 1.60837851487422766e-2,
                                  6.58749161529837803e-4, 1.63153871373020978e-2};
  static constexpr double q[5] = {2.56852019228982242e00, 1.87295284992346047e00,
                                  5.27905102951428412e-1, 6.05183413124413191e-2,
                                  2.33520497626869185e-3};
  constexpr double kRsqrtPi = 5.6418958354775628695e-1;
  const V<D> one = C(d, 1.0);
  const V<D> y = hn::Min(hn::Abs(x), C(d, 26.543));
  const V<D> ysq = hn::Mul(y, y);
  const Mk<D> is_small = hn::Le(y, C(d, 0.46875)), is_mid = hn::Le(y, C(d, 4.0));
  V<D> small = one, mid = one, tail = one, num, den;
  if (!hn::AllFalse(d, is_small)) {  // |x| <= 0.46875
    num = hn::Mul(C(d, a[4]), ysq);
    den = ysq;
    for (int i = 0; i < 3; ++i) {
      num = hn::Mul(hn::Add(num, C(d, a[i])), ysq);
      den = hn::Mul(hn::Add(den, C(d, b[i])), ysq);
    }
    small = hn::Sub(one, hn::Div(hn::Mul(x, hn::Add(num, C(d, a[3]))), hn::Add(den, C(d, b[3]))));
  }
  if (!hn::AllFalse(d, hn::AndNot(is_small, is_mid))) {  // 0.46875 < |x| <= 4
    num = hn::Mul(C(d, c[8]), y);
    den = y;
    for (int i = 0; i < 7; ++i) {
      num = hn::Mul(hn::Add(num, C(d, c[i])), y);
      den = hn::Mul(hn::Add(den, C(d, dd[i])), y);
    }
    mid = hn::Div(hn::Add(num, C(d, c[7])), hn::Add(den, C(d, dd[7])));
  }
  if (!hn::AllTrue(d, is_mid)) {  // |x| > 4
    const V<D> z = hn::Div(one, ysq);
    num = hn::Mul(C(d, p[5]), z);
    den = z;
    for (int i = 0; i < 4; ++i) {
      num = hn::Mul(hn::Add(num, C(d, p[i])), z);
      den = hn::Mul(hn::Add(den, C(d, q[i])), z);
    }
    tail = hn::Div(hn::Sub(C(d, kRsqrtPi),
                           hn::Div(hn::Mul(z, hn::Add(num, C(d, p[4]))), hn::Add(den, C(d, q[4])))),
                   y);
  }
  const V<D> t = hn::Mul(hn::Trunc(hn::Mul(y, C(d, 16.0))), C(d, 1.0 / 16.0));
  const V<D> del = hn::Mul(hn::Sub(y, t), hn::Add(y, t));
  gauss = hn::Mul(hn::Exp(d, hn::Neg(hn::Mul(t, t))), hn::Exp(d, hn::Neg(del)));
  gauss = hn::IfThenElse(hn::Ge(y, C(d, 26.543)), hn::Zero(d), gauss);
  V<D> big = hn::Mul(gauss, hn::IfThenElse(is_mid, mid, tail));
  big = hn::IfThenElse(hn::Lt(x, hn::Zero(d)), hn::Sub(C(d, 2.0), big), big);
  return hn::IfThenElse(is_small, small, big);
}

// physics::gauss_terms: the Gaussian f_u of standard deviation s at y, its CDF F, A = int F and
// Y = int y F(y) dy. The density's exp(-y^2 / (2 s^2)) is the erfc's exp(-z^2), z = -y/(s sqrt 2)
// (the scalar evaluates exp(-0.5 (y/s)^2) apart: the two differ by the rounding of the exponent).
template <class D>
struct GaussLanes {
  V<D> F, f, A, Y;
};
template <class D>
HWY_INLINE GaussLanes<D> gauss_terms(D d, V<D> y, V<D> s) {
  V<D> gauss;
  const V<D> F = hn::Mul(
      C(d, 0.5), erfc_cody(d, hn::Div(hn::Neg(y), hn::Mul(s, C(d, std::sqrt(2.0)))), gauss));
  const V<D> f = hn::Div(gauss, hn::Mul(s, C(d, std::sqrt(2.0 * physics::kPi))));
  const V<D> s2 = hn::Mul(s, s);
  const V<D> A = hn::Add(hn::Mul(y, F), hn::Mul(s2, f));
  const V<D> B = hn::Add(hn::Mul(hn::Mul(C(d, 0.5), hn::Add(hn::Mul(y, y), s2)), F),
                         hn::Mul(hn::Mul(hn::Mul(hn::Mul(C(d, 0.5), y), s), s), f));
  return {F, f, A, hn::Sub(hn::Mul(y, A), B)};
}

// The Preisach constants of one rod over the lanes (RodConditions::preisach, MsT_mag).
template <class D>
struct PreisachLaneConstants {
  V<D> MsT, c, alpha, a, inv_a, inv_hc, s;
  V<D> edge[physics::kPreisachBins + 1], density[physics::kPreisachBins];
};

// physics::everett over the lanes: the triangle T(a, b) (a may be +inf, b -inf: then side_a is
// {q - p, (q^2 - p^2)/2, 0}, side_b nothing), each bin where its lower edge is below D = (a - b)/2
// (inf if a side is), the upper limit min(edge, D). A bin's upper Gaussian terms are the next
// bin's lower ones wherever that bin counts (its p is this one's q), so they are evaluated once.
template <class D>
struct EverettLanes {
  V<D> E, Ec, Eu, dE_da, dE_db;
};
template <class D>
HWY_NOINLINE EverettLanes<D> everett(D d, const PreisachLaneConstants<D>& k, V<D> a, V<D> b) {
  const V<D> zero = hn::Zero(d), s = k.s;
  EverettLanes<D> e{zero, zero, zero, zero, zero};
  const Mk<D> a_inf = hn::IsInf(a), b_inf = hn::IsInf(b), valid = hn::Gt(a, b);
  const V<D> Dl =
      hn::IfThenElse(hn::Or(a_inf, b_inf), C(d, HUGE_VAL), hn::Mul(C(d, 0.5), hn::Sub(a, b)));
  const V<D> af = hn::IfThenElse(a_inf, zero, a), bf = hn::IfThenElse(b_inf, zero, b);
  GaussLanes<D> ga_p = gauss_terms(d, hn::Sub(af, k.edge[0]), s);
  GaussLanes<D> gb_p = gauss_terms(d, hn::Add(bf, k.edge[0]), s);
  for (int j = 0; j < physics::kPreisachBins; ++j) {
    const Mk<D> active = hn::And(valid, hn::Lt(k.edge[j], Dl));
    if (hn::AllFalse(d, active)) break;
    const V<D> p = k.edge[j], q = hn::Min(k.edge[j + 1], Dl), w = k.density[j];
    const GaussLanes<D> ga_q = gauss_terms(d, hn::Sub(af, q), s);
    const GaussLanes<D> gb_q = gauss_terms(d, hn::Add(bf, q), s);
    const V<D> dA_a = hn::Sub(ga_p.A, ga_q.A);
    V<D> I0a = dA_a, I1a = hn::Sub(hn::Mul(af, dA_a), hn::Sub(ga_p.Y, ga_q.Y));
    V<D> Ja = hn::Sub(ga_p.F, ga_q.F);
    I0a = hn::IfThenElse(a_inf, hn::Sub(q, p), I0a);
    I1a = hn::IfThenElse(a_inf, hn::Mul(C(d, 0.5), hn::Sub(hn::Mul(q, q), hn::Mul(p, p))), I1a);
    Ja = hn::IfThenElse(a_inf, zero, Ja);
    const V<D> dA_b = hn::Sub(gb_q.A, gb_p.A);
    const V<D> I0b = hn::IfThenElse(b_inf, zero, dA_b);
    const V<D> I1b =
        hn::IfThenElse(b_inf, zero, hn::Sub(hn::Sub(gb_q.Y, gb_p.Y), hn::Mul(bf, dA_b)));
    const V<D> Jb = hn::IfThenElse(b_inf, zero, hn::Sub(gb_q.F, gb_p.F));
    e.E = hn::Add(e.E, hn::IfThenElse(active, hn::Mul(w, hn::Sub(I0a, I0b)), zero));
    e.Ec = hn::Add(e.Ec, hn::IfThenElse(active, hn::Mul(w, hn::Sub(I1a, I1b)), zero));
    e.Eu = hn::Add(
        e.Eu, hn::IfThenElse(active, hn::Mul(hn::Mul(hn::Mul(w, s), s), hn::Sub(Jb, Ja)), zero));
    e.dE_da = hn::Add(e.dE_da, hn::IfThenElse(active, hn::Mul(w, Ja), zero));
    e.dE_db = hn::Sub(e.dE_db, hn::IfThenElse(active, hn::Mul(w, Jb), zero));
    ga_p = ga_q;
    gb_p = gb_q;
  }
  return e;
}

// physics::preisach_point over the lanes at reduced inputs x: each lane's base extremum found on
// its own stack (physics::preisach_base, lane by lane), the triangle from it over the lanes.
template <class D>
struct PreisachPointLanes {
  V<D> mu, mc, mu_u, dmu_dx;
};
template <class D>
HWY_NOINLINE PreisachPointLanes<D> preisach_point(D d, const PreisachLaneConstants<D>& k,
                                                  const physics::PreisachHistory* h, V<D> x) {
  constexpr std::size_t W = kPad;  // the widest vector's lanes (lane_data.hpp)
  const std::size_t n = hn::Lanes(d);
  double xs[W], xb[W], mub[W], mcb[W], mubu[W], up[W], same[W];
  hn::StoreU(x, d, xs);
  for (std::size_t l = 0; l < n; ++l) {
    const physics::PreisachBase b = physics::preisach_base(h[l], xs[l]);
    xb[l] = b.xb;
    mub[l] = b.mub;
    mcb[l] = b.mcb;
    mubu[l] = b.mub_u;
    up[l] = b.up ? 1.0 : 0.0;
    same[l] = b.same ? 1.0 : 0.0;
  }
  const V<D> vxb = hn::LoadU(d, xb), vmub = hn::LoadU(d, mub), vmcb = hn::LoadU(d, mcb),
             vmubu = hn::LoadU(d, mubu);
  const Mk<D> vup = hn::Ne(hn::LoadU(d, up), hn::Zero(d));
  const Mk<D> vsame = hn::Ne(hn::LoadU(d, same), hn::Zero(d));
  // up: T(x, xb) switches up; down: T(xb, x) switches down; same: nothing (a = b)
  const V<D> a = hn::IfThenElse(vsame, hn::Zero(d), hn::IfThenElse(vup, x, vxb));
  const V<D> b = hn::IfThenElse(vsame, hn::Zero(d), hn::IfThenElse(vup, vxb, x));
  const EverettLanes<D> e = everett(d, k, a, b);
  PreisachPointLanes<D> r;
  r.mu = hn::IfThenElse(vup, hn::Add(vmub, e.E), hn::Sub(vmub, e.E));
  r.mc = hn::IfThenElse(vup, hn::Add(vmcb, e.Ec), hn::Sub(vmcb, e.Ec));
  r.mu_u = hn::IfThenElse(vup, hn::Add(vmubu, e.Eu), hn::Sub(vmubu, e.Eu));
  r.dmu_dx = hn::IfThenElse(vup, e.dE_da, hn::Neg(e.dE_db));
  r.mu = hn::IfThenElse(vsame, vmub, r.mu);
  r.mc = hn::IfThenElse(vsame, vmcb, r.mc);
  r.mu_u = hn::IfThenElse(vsame, vmubu, r.mu_u);
  r.dmu_dx = hn::IfThenElse(vsame, hn::Zero(d), r.dmu_dx);
  return r;
}

// What a trial leaves for the commit: the reduced input x1 the move ends at and the point there.
template <class D>
struct PreisachLaneTrial {
  V<D> M, dM_dH, Mirr, inv_mu_r, M_next;
  V<D> an_x, an_L, an_dL;  // the rod's own (the law does not evaluate M_an between steps)
  Mk<D> converged, solved;
  V<D> x1, mu, mc, mu_u;
  Mk<D> moved;
};

// physics::preisach_magnetisation at the end field H1 in the lanes of `todo`: Newton on
// g(M) = M - M_s [(1 - c)(2 mu(x) - 1) + c L(H_e / a)], steps -g / max(1 - alpha chi_e, 0.2),
// each lane stopping where |g| <= 1e-12 M_s^T or at the 60th evaluation, with that evaluation's
// M, chi_e, x and point; t.dM_dH = chi_e / (1 - alpha chi_e).
template <class D>
HWY_INLINE void preisach_solve(D d, Mk<D> todo, const PreisachLaneConstants<D>& k,
                               const physics::PreisachHistory* h, V<D> H1, V<D> M_guess,
                               PreisachLaneTrial<D>& t) {
  const V<D> one = C(d, 1.0), tol = hn::Mul(C(d, 1e-12), k.MsT), one_c = hn::Sub(one, k.c);
  V<D> M = M_guess, chi = hn::Zero(d);
  Mk<D> left = todo;
  for (int it = 0; it < 60 && !hn::AllFalse(d, left); ++it) {
    const V<D> He = hn::Add(H1, hn::Mul(k.alpha, M));
    const V<D> x = hn::Mul(He, k.inv_hc);
    const PreisachPointLanes<D> pt = preisach_point(d, k, h, x);
    V<D> L, dL;
    langevin_pair(d, hn::Mul(He, k.inv_a), L, dL);
    const V<D> Mnew = hn::Mul(
        k.MsT, hn::Add(hn::Mul(one_c, hn::Sub(hn::Mul(C(d, 2.0), pt.mu), one)), hn::Mul(k.c, L)));
    const V<D> chi_e =
        hn::Mul(k.MsT, hn::Add(hn::Mul(hn::Mul(hn::Mul(one_c, C(d, 2.0)), pt.dmu_dx), k.inv_hc),
                               hn::Mul(hn::Mul(k.c, dL), k.inv_a)));
    const V<D> g = hn::Sub(M, Mnew);
    const Mk<D> stop =
        hn::And(left, it == 59 ? hn::FirstN(d, hn::Lanes(d)) : hn::Le(hn::Abs(g), tol));
    t.M = hn::IfThenElse(stop, Mnew, t.M);
    chi = hn::IfThenElse(stop, chi_e, chi);
    t.x1 = hn::IfThenElse(stop, x, t.x1);
    t.mu = hn::IfThenElse(stop, pt.mu, t.mu);
    t.mc = hn::IfThenElse(stop, pt.mc, t.mc);
    t.mu_u = hn::IfThenElse(stop, pt.mu_u, t.mu_u);
    left = hn::AndNot(stop, left);
    V<D> dg = hn::Sub(one, hn::Mul(k.alpha, chi_e));
    dg = hn::IfThenElse(hn::Lt(dg, C(d, 0.2)), C(d, 0.2), dg);  // alpha > 0: damp the step
    M = hn::IfThenElse(left, hn::Sub(M, hn::Div(g, dg)), M);
  }
  t.dM_dH = hn::IfThenElse(todo, hn::Div(chi, hn::Sub(one, hn::Mul(k.alpha, chi))), t.dM_dH);
}

// The law's lane entry (PreisachLaw's begin_move / joint_trial / commit_trial over the lanes).
// Its state per rod: the lane's extrema stack (LaneData::pre) and M_irr = M_s (1 - c)(2 mu - 1)
// (kMirr, what commit_trial records). A joint trial solves the law at H1 fully from M_iter (the
// law's inner Newton, trial_from), so M_next = M and it has converged; where H1 = H0 nothing
// moves and the slope is the reversible part's (preisach_reversible_susceptibility).
struct PreisachLanes {
  template <class D>
  using Constants = PreisachLaneConstants<D>;
  template <class D>
  struct Start {};
  template <class D>
  struct Rod {
    V<D> H, Mirr, M, an_x, an_L, an_dL;
    physics::PreisachHistory* h;  // the stacks of the chunk's lanes
  };
  template <class D>
  using Trial = PreisachLaneTrial<D>;
  template <class D>
  static Start<D> begin_move(D, const Constants<D>&, const Rod<D>&) {
    return {};
  }
  template <class D>
  static HWY_INLINE Trial<D> joint_trial(D d, const Constants<D>& k, const Rod<D>& r,
                                         const Start<D>&, V<D> H1, V<D> M_iter, Mk<D>) {
    const V<D> one = C(d, 1.0);
    Trial<D> t;
    t.moved = hn::Not(hn::Eq(H1, r.H));
    t.M = r.M;
    t.dM_dH = t.x1 = t.mu = t.mc = t.mu_u = hn::Zero(d);
    if (!hn::AllTrue(d, t.moved)) {  // preisach_reversible_susceptibility at (H0, M0)
      V<D> L0, dL0;
      langevin_pair(d, hn::Div(hn::Add(r.H, hn::Mul(k.alpha, r.M)), k.a), L0, dL0);
      const V<D> chi_e = hn::Mul(hn::Div(hn::Mul(k.c, k.MsT), k.a), dL0);
      t.dM_dH = hn::Div(chi_e, hn::Sub(one, hn::Mul(k.alpha, chi_e)));
    }
    if (!hn::AllFalse(d, t.moved)) preisach_solve(d, t.moved, k, r.h, H1, M_iter, t);
    t.M = hn::IfThenElse(t.moved, t.M, r.M);
    t.inv_mu_r = hn::Div(one, hn::Add(one, t.dM_dH));
    t.M_next = t.M;
    t.converged = hn::FirstN(d, hn::Lanes(d));
    t.solved = hn::FirstN(d, 0);
    // commit_trial's M_irr = M_s (1 - c)(2 mu - 1) where the move commits
    t.Mirr = hn::IfThenElse(
        t.moved, hn::Mul(hn::Mul(k.MsT, hn::Sub(one, k.c)), hn::Sub(hn::Mul(C(d, 2.0), t.mu), one)),
        r.Mirr);
    t.an_x = r.an_x;
    t.an_L = r.an_L;
    t.an_dL = r.an_dL;
    return t;
  }
};

// The kernel's hooks (step_kernel-inl.h, step_lanes.cpp): the rod's constants and state at the
// step's start, the trial a lane keeps (take_trial), and the commit of the stacks of the lanes
// that keep the step (PreisachLaw::commit_trial: the trial's measure committed at x1 with
// preisach_commit_point, the distribution not evaluated again; nothing moved: no loss).
template <class D>
HWY_INLINE void law_rod(const Chunk<D>& c, const RodStates<D>& s, int i,
                        PreisachLaneConstants<D>& k, PreisachLanes::Rod<D>& r) {
  const int rods = c.L.st.rods;
  auto f = [&](int field) { return hn::LoadU(c.d, c.L.pre.field(field, i, rods) + c.j); };
  k.MsT = c.rod(kMsTMag, i);
  k.c = f(kPreC);
  k.alpha = f(kPreAlpha);
  k.a = f(kPreA);
  k.inv_a = f(kPreInvA);
  k.inv_hc = f(kPreInvHc);
  k.s = f(kPreSigmaU);
  for (int b = 0; b <= physics::kPreisachBins; ++b) k.edge[b] = f(kPreEdge0 + b);
  for (int b = 0; b < physics::kPreisachBins; ++b) k.density[b] = f(kPreDensity0 + b);
  r = {s.f[kH][i],    s.f[kMirr][i],           s.f[kM][i], s.f[kAnX][i], s.f[kAnL][i],
       s.f[kAnDL][i], c.L.pre.history(i) + c.j};
}

template <class D, class M>
HWY_INLINE void take_trial(D, M done, M /*real*/, const PreisachLaneTrial<D>& t,
                           PreisachLaneTrial<D>& tr, std::size_t&) {
  keep_common_trial(done, t, tr);
  tr.x1 = hn::IfThenElse(done, tr.x1, t.x1);
  tr.mu = hn::IfThenElse(done, tr.mu, t.mu);
  tr.mc = hn::IfThenElse(done, tr.mc, t.mc);
  tr.mu_u = hn::IfThenElse(done, tr.mu_u, t.mu_u);
  tr.solved = hn::Or(hn::And(done, tr.solved), hn::AndNot(done, t.solved));
  tr.moved = hn::Or(hn::And(done, tr.moved), hn::AndNot(done, t.moved));
}

template <class D>
HWY_INLINE void commit_law_state(const Magnetic<PreisachLanes, D>&, RodStates<D>&, int) {}
template <class D>
HWY_INLINE void law_commit(const Chunk<D>& c, const Magnetic<PreisachLanes, D>& mg, Mk<D> keep) {
  const D d = c.d;
  constexpr std::size_t W = kPad;
  const std::size_t n = hn::Lanes(d);
  double kept[W], moved[W], x1[W], mu[W], mc[W], mu_u[W];
  hn::StoreU(hn::IfThenElseZero(keep, C(d, 1.0)), d, kept);
  for (int i = 0; i < c.n; ++i) {
    const auto& tr = mg.trial[i];
    hn::StoreU(hn::IfThenElseZero(tr.moved, C(d, 1.0)), d, moved);
    hn::StoreU(tr.x1, d, x1);
    hn::StoreU(tr.mu, d, mu);
    hn::StoreU(tr.mc, d, mc);
    hn::StoreU(tr.mu_u, d, mu_u);
    physics::PreisachHistory* h = c.L.pre.history(i) + c.j;
    for (std::size_t l = 0; l < n; ++l) {
      if (kept[l] == 0.0) continue;
      if (moved[l] == 0.0) {
        h[l].last_dmc = 0.0;
        continue;
      }
      physics::PreisachPoint p;
      p.mu = mu[l];
      p.mc = mc[l];
      p.mu_u = mu_u[l];
      p.base = physics::preisach_base(h[l], x1[l]).base;
      physics::preisach_commit_point(h[l], x1[l], p);
    }
  }
}

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // GMASIM_LANES_PREISACH_INL_H_
