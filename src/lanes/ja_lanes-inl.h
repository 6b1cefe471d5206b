// The Jiles-Atherton law (eq. 9) over SIMD lanes: the magnetisation-law seam's lane entry
// (docs/lanes.md, "Laws"). One function per law of gmasim/physics/jiles_atherton.hpp and
// magnetic.hpp, operation for operation the scalar code, branches replaced by per-lane
// selects; D is any Highway tag (width 1 is the reference instance). Included once per target
// by src/lanes/step_lanes.cpp (hwy/foreach_target.h).
#if defined(GMASIM_LANES_JA_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef GMASIM_LANES_JA_INL_H_
#undef GMASIM_LANES_JA_INL_H_
#else
#define GMASIM_LANES_JA_INL_H_
#endif

#include "gmasim/physics/jiles_atherton.hpp"
#include "hwy/contrib/math/math-inl.h"
#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace gmasim::lanes::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

template <class D>
using V = hn::Vec<D>;
template <class D>
using Mk = hn::Mask<D>;

template <class D>
HWY_INLINE V<D> C(D d, double x) {
  return hn::Set(d, x);
}

// c0 + c1 x + ... + c7 x^7 by Estrin's scheme (series.hpp, polynomial7).
template <class D>
HWY_INLINE V<D> polynomial7(D d, V<D> x, const double (&c)[8]) {
  const V<D> x2 = hn::Mul(x, x), x4 = hn::Mul(x2, x2);
  const V<D> p01 = hn::Add(C(d, c[0]), hn::Mul(C(d, c[1]), x));
  const V<D> p23 = hn::Add(C(d, c[2]), hn::Mul(C(d, c[3]), x));
  const V<D> p45 = hn::Add(C(d, c[4]), hn::Mul(C(d, c[5]), x));
  const V<D> p67 = hn::Add(C(d, c[6]), hn::Mul(C(d, c[7]), x));
  return hn::Add(hn::Add(p01, hn::Mul(x2, p23)), hn::Mul(x4, hn::Add(p45, hn::Mul(x2, p67))));
}

// e^x to (x^8 / 8!) where |x| <= 1/64 (series.hpp, exp_series7).
template <class D>
HWY_INLINE V<D> exp_series7(D d, V<D> x) {
  constexpr double kExp[8] = {1.0,      1.0,       1.0 / 2,   1.0 / 6,
                              1.0 / 24, 1.0 / 120, 1.0 / 720, 1.0 / 5040};
  return polynomial7(d, x, kExp);
}

// A known exponential per lane, e = e^y (series.hpp, ExpPoint; y NaN: none).
template <class D>
struct ExpLanes {
  V<D> y, e;
};
// series.hpp's exp_near per lane: e^y from the known e^{y_prev} where |y - y_prev| <= 1/64
// (e^{y_prev} exp_series7(y - y_prev)), hn::Exp elsewhere (computed only where a lane needs
// it). The lanes of `update` take (y, e^y) as their point.
template <class D>
HWY_INLINE V<D> exp_near(D d, V<D> y, ExpLanes<D>& p, Mk<D> update) {
  const V<D> dy = hn::Sub(y, p.y);
  const Mk<D> near = hn::Le(hn::Abs(dy), C(d, 1.0 / 64));  // false where y_prev is NaN
  V<D> e;
  if (hn::AllFalse(d, near))  // a move's first evaluation
    e = hn::Exp(d, y);
  else if (hn::AllTrue(d, near))
    e = hn::Mul(p.e, exp_series7(d, dy));
  else
    e = hn::IfThenElse(near, hn::Mul(p.e, exp_series7(d, dy)), hn::Exp(d, y));
  p.y = hn::IfThenElse(update, y, p.y);
  p.e = hn::IfThenElse(update, e, p.e);
  return e;
}
// The exponentials of a law evaluation, for the next one nearby (jiles_atherton.hpp,
// JaExpPoints): exp(-2|x|) of the Langevin function and exp(-r) of the lag.
template <class D>
struct JaExpLanes {
  ExpLanes<D> langevin, lag;
};
template <class D>
HWY_INLINE JaExpLanes<D> no_exp_points(D d) {
  const V<D> nan = hn::Set(d, __builtin_nan("")), zero = hn::Zero(d);
  return {{nan, zero}, {nan, zero}};
}

// Langevin function and slope (jiles_atherton.hpp, langevin_pair): L = coth x - 1/x,
// L' = 1/x^2 - 1/sinh^2 x from one exponential and one division (q = 1/(x (1 - e)) gives 1/x
// and 1/(1 - e)), Taylor series for |x| < 0.1. Beyond |x| = 40, e < 2e-35 and 1 - e = 1: the
// same q is 1/x, as the scalar's large-x branch divides.
// With `near` (langevin_pair_near), exp(-2|x|) by exp_near from its point; the lanes of `update`
// where the closed form applies take this one's.
template <class D>
HWY_INLINE void langevin_pair(D d, V<D> x, V<D>& L, V<D>& dL, ExpLanes<D>* near = nullptr,
                              Mk<D> update = Mk<D>()) {
  const V<D> ax = hn::Abs(x);
  const V<D> y = hn::Mul(C(d, -2.0), ax);
  const Mk<D> closed = hn::And(hn::Ge(ax, C(d, 0.1)), hn::Le(ax, C(d, 40.0)));
  const V<D> e = near ? exp_near(d, y, *near, hn::And(update, closed))
                      : hn::Exp(d, y);  // coth|x| = (1 + e)/(1 - e)
  const V<D> ome = hn::Sub(C(d, 1.0), e);
  const V<D> q = hn::Div(C(d, 1.0), hn::Mul(x, ome));
  const V<D> inv_x = hn::Mul(ome, q);
  const V<D> inv_1me = hn::Mul(x, q);
  const V<D> coth_abs = hn::Mul(hn::Add(C(d, 1.0), e), inv_1me);
  const V<D> inv_sinh2 = hn::Mul(hn::Mul(hn::Mul(C(d, 4.0), e), inv_1me), inv_1me);
  const V<D> inv_x2 = hn::Mul(inv_x, inv_x);
  const Mk<D> pos = hn::Gt(x, hn::Zero(d));
  const V<D> Lb = hn::Sub(hn::IfThenElse(pos, C(d, 1.0), C(d, -1.0)), inv_x);
  const V<D> Lm = hn::Sub(hn::IfThenElse(pos, coth_abs, hn::Neg(coth_abs)), inv_x);
  const V<D> dLm = hn::Sub(inv_x2, inv_sinh2);
  const Mk<D> big = hn::Gt(ax, C(d, 40.0));
  L = hn::IfThenElse(big, Lb, Lm);
  dL = hn::IfThenElse(big, inv_x2, dLm);
  const Mk<D> small = hn::Lt(ax, C(d, 0.1));
  if (hn::AllFalse(d, small)) return;  // the series only where a lane needs it
  const V<D> x2 = hn::Mul(x, x);
  const V<D> Lt = hn::Mul(
      x,
      hn::Sub(
          C(d, 1.0 / 3.0),
          hn::Mul(
              x2,
              hn::Sub(
                  C(d, 1.0 / 45.0),
                  hn::Mul(x2, hn::Sub(C(d, 2.0 / 945.0),
                                      hn::Mul(x2, hn::Sub(C(d, 1.0 / 4725.0),
                                                          hn::Mul(x2, C(d, 2.0 / 93555.0))))))))));
  const V<D> dLt = hn::Sub(
      C(d, 1.0 / 3.0),
      hn::Mul(
          x2,
          hn::Sub(C(d, 1.0 / 15.0),
                  hn::Mul(x2, hn::Sub(C(d, 2.0 / 189.0),
                                      hn::Mul(x2, hn::Sub(C(d, 1.0 / 675.0),
                                                          hn::Mul(x2, C(d, 2.0 / 10395.0)))))))));
  L = hn::IfThenElse(small, Lt, L);
  dL = hn::IfThenElse(small, dLt, dL);
}

// exp(-r), q(r) = (1 - exp(-r))/r and dq/dr = (E - q)/r (magnetic.hpp, lag_weights_and_slope_from):
// Taylor series for q at r < 1e-2 (where dq/dr divides by r, and is -1/2 at r <= 1e-12), one
// reciprocal of r beyond; one division per lane either way.
// With `near` (lag_weights_and_slope_near), exp(-r) by exp_near; the lanes of `update` take it.
template <class D>
HWY_INLINE void lag_weights_and_slope(D d, V<D> r, V<D>& E, V<D>& q, V<D>& dq_dr, ExpLanes<D>* near,
                                      Mk<D> update) {
  E = near ? exp_near(d, hn::Neg(r), *near, update) : hn::Exp(d, hn::Neg(r));
  const V<D> qt = hn::Sub(
      C(d, 1.0),
      hn::Mul(
          r,
          hn::Sub(
              C(d, 1.0 / 2),
              hn::Mul(
                  r, hn::Sub(
                         C(d, 1.0 / 6),
                         hn::Mul(r, hn::Sub(C(d, 1.0 / 24),
                                            hn::Mul(r, hn::Sub(C(d, 1.0 / 120),
                                                               hn::Mul(r, C(d, 1.0 / 720)))))))))));
  const Mk<D> small = hn::Lt(r, C(d, 1e-2));
  const V<D> quot = hn::Div(hn::IfThenElse(small, hn::Sub(E, qt), C(d, 1.0)), r);
  const V<D> qm = hn::Mul(hn::Sub(C(d, 1.0), E), quot);  // quot = 1/r here
  q = hn::IfThenElse(small, qt, qm);
  dq_dr = hn::IfThenElse(small, hn::IfThenElse(hn::Gt(r, C(d, 1e-12)), quot, C(d, -0.5)),
                         hn::Mul(hn::Sub(E, qm), quot));
}

// Eq. (9), second line, integrated over one step (jiles_atherton.hpp,
// ja_irreversible_update): M_irr relaxes towards M_an along the path length with "time
// constant" k, pinned while (M_an - M_irr) delta <= 0. Returns M_irr1; dMirr = dM_irr1/dH_e1.
// inv_k = 1/k; exp(-r) from `near` where given (its lanes of `update` that move take it).
template <class D>
HWY_INLINE V<D> ja_irreversible_update(D d, V<D> Mirr0, V<D> Man0, V<D> Man1, V<D> dMan1, V<D> dHe,
                                       V<D> inv_k, V<D>& dMirr, ExpLanes<D>* near, Mk<D> update) {
  const V<D> zero = hn::Zero(d);
  const V<D> delta = hn::IfThenElse(hn::Gt(dHe, zero), C(d, 1.0), C(d, -1.0));
  const V<D> d0 = hn::Mul(hn::Sub(Man0, Mirr0), delta);
  const V<D> d1 = hn::Mul(hn::Sub(Man1, Mirr0), delta);
  const Mk<D> still = hn::Or(hn::Eq(dHe, zero), hn::And(hn::Le(d0, zero), hn::Le(d1, zero)));
  const Mk<D> cross = hn::Le(d0, zero);  // M_an crosses M_irr inside the step
  V<D> s = hn::Abs(dHe), ds = delta;
  if (!hn::AllFalse(d, hn::AndNot(still, cross))) {  // only where a lane needs it
    const V<D> frac = hn::Div(d1, hn::Sub(d1, d0));
    const V<D> d10 = hn::Sub(d1, d0);
    const V<D> ds_cross =
        hn::Sub(hn::Mul(delta, frac),
                hn::Div(hn::Mul(hn::Mul(hn::Mul(s, d0), delta), dMan1), hn::Mul(d10, d10)));
    ds = hn::IfThenElse(cross, ds_cross, delta);
    s = hn::IfThenElse(cross, hn::Mul(s, frac), s);
  }
  const V<D> u0 = hn::IfThenElse(cross, Mirr0, Man0);
  const V<D> r = hn::Mul(s, inv_k);
  V<D> E, q, dq_dr;
  lag_weights_and_slope(d, r, E, q, dq_dr, near, hn::AndNot(still, update));
  const V<D> a0 = hn::Sub(Mirr0, u0), a1 = hn::Sub(Man1, u0);
  const V<D> dm =
      hn::Add(hn::Mul(hn::Sub(C(d, 1.0), q), dMan1),
              hn::Mul(hn::Mul(ds, inv_k), hn::Sub(hn::Mul(hn::Neg(a0), E), hn::Mul(a1, dq_dr))));
  dMirr = hn::IfThenElse(still, zero, dm);
  const V<D> m1 = hn::Sub(hn::Add(Man1, hn::Mul(a0, E)), hn::Mul(a1, q));
  return hn::IfThenElse(still, Mirr0, m1);
}

// The JA constants of one rod over the lanes (RodConditions::ja, MsT_mag).
template <class D>
struct JaLaneConstants {
  V<D> MsT, a, alpha, c, k;
  V<D> inv_a;  // 1/a (the scalar law's 1.0 / a_A_per_m, packed once: LaneData kJaInvA)
  V<D> inv_k;  // 1/k (JaMoveStart::inv_k: LaneData kJaInvK)
};

// What a move depends on at its start only (jiles_atherton.hpp, ja_move_start_near): H_e0 and
// M_an(H_e0), fixed while the consistent state's Newton solve tries several end fields. Where
// the law's last evaluation (x_at = H_e / a, L and L' there: the rod's kAnX, kAnL, kAnDL) is
// within 1e-7 of x0 = H_e0 / a, M_an(H_e0) = M_s^T (L + L' (x0 - x_at)); elsewhere (x_at NaN:
// nothing known) the Langevin function at x0, computed only where a lane needs it.
// `near`: the exponentials of the move's last evaluation (none at its start).
template <class D>
struct JaLaneStart {
  V<D> He0, Man0;
  JaExpLanes<D> near;
};
template <class D>
HWY_INLINE JaLaneStart<D> ja_move_start(D d, V<D> H0, V<D> M0, const JaLaneConstants<D>& p,
                                        V<D> x_at, V<D> L_at, V<D> dL_at) {
  const V<D> He0 = hn::Add(H0, hn::Mul(p.alpha, M0));
  const V<D> x0 = hn::Mul(He0, p.inv_a);
  const V<D> dx = hn::Sub(x0, x_at);
  const Mk<D> near = hn::Le(hn::Abs(dx), C(d, 1e-7));
  V<D> L = hn::Add(L_at, hn::Mul(dL_at, dx));
  if (!hn::AllTrue(d, near)) {
    V<D> Lx, dLx;
    langevin_pair(d, x0, Lx, dLx);
    L = hn::IfThenElse(near, L, Lx);
  }
  return {He0, hn::Mul(p.MsT, L), no_exp_points(d)};
}

// One evaluation of eq. (9) at the end field H1 and a magnetisation iterate M1 (jiles_atherton.hpp,
// ja_evaluate): M_irr1, F(M1) = (1-c) M_irr1 + c M_an(H1 + alpha M1) and chi_e = dF/dH_e. With
// `near`, its exponentials from the move's last evaluation (the lanes of `update` take these).
template <class D>
struct JaLaneEvaluation {
  V<D> Mirr1, M, chi_e;
  V<D> x1, L1, dL1;  // where the Langevin function was evaluated (H_e1 / a), L and L' there
};
template <class D>
HWY_INLINE JaLaneEvaluation<D> ja_evaluate(D d, const JaLaneStart<D>& st, V<D> H1, V<D> M1,
                                           const JaLaneConstants<D>& p, V<D> Mirr0, V<D> inv_a,
                                           JaExpLanes<D>* near = nullptr, Mk<D> update = Mk<D>()) {
  const V<D> He1 = hn::Add(H1, hn::Mul(p.alpha, M1));
  const V<D> x1 = hn::Mul(He1, inv_a);
  V<D> L1, dL1;
  langevin_pair(d, x1, L1, dL1, near ? &near->langevin : nullptr, update);
  const V<D> Man1 = hn::Mul(p.MsT, L1);
  const V<D> dMan = hn::Mul(hn::Mul(p.MsT, inv_a), dL1);
  V<D> dMirr;
  const V<D> Mirr1 = ja_irreversible_update(d, Mirr0, st.Man0, Man1, dMan, hn::Sub(He1, st.He0),
                                            p.inv_k, dMirr, near ? &near->lag : nullptr, update);
  const V<D> one_c = hn::Sub(C(d, 1.0), p.c);
  return {Mirr1,
          hn::Add(hn::Mul(one_c, Mirr1), hn::Mul(p.c, Man1)),
          hn::Add(hn::Mul(one_c, dMirr), hn::Mul(p.c, dMan)),
          x1,
          L1,
          dL1};
}

// Eq. (9) solved at H1 by Newton's method in the lanes of `todo` (jiles_atherton.hpp,
// ja_step_from for H1 != H0): from M_guess, steps -g / max(1 - alpha chi_e, 0.2), each lane
// stopping where |g| <= 1e-12 M_s^T or at the 60th evaluation with that evaluation's M_irr1,
// M and chi_e. The lanes outside todo keep e's values. Out of line: the rare path, so that
// joint_trial's common one inlines into the Newton loop.
template <class D>
HWY_NOINLINE void ja_solve(D d, Mk<D> todo, const JaLaneStart<D>& st, V<D> H1, V<D> M_guess,
                           const JaLaneConstants<D>& p, V<D> Mirr0, V<D> inv_a,
                           JaLaneEvaluation<D>& e) {
  const V<D> tol = hn::Mul(C(d, 1e-12), p.MsT);
  V<D> M1 = M_guess;
  Mk<D> left = todo;
  for (int it = 0; it < 60 && !hn::AllFalse(d, left); ++it) {
    const JaLaneEvaluation<D> ev = ja_evaluate(d, st, H1, M1, p, Mirr0, inv_a);
    const V<D> g = hn::Sub(M1, ev.M);
    const Mk<D> stop =
        hn::And(left, it == 59 ? hn::FirstN(d, hn::Lanes(d)) : hn::Le(hn::Abs(g), tol));
    e.Mirr1 = hn::IfThenElse(stop, ev.Mirr1, e.Mirr1);
    e.M = hn::IfThenElse(stop, ev.M, e.M);
    e.chi_e = hn::IfThenElse(stop, ev.chi_e, e.chi_e);
    left = hn::AndNot(stop, left);
    V<D> dg = hn::Sub(C(d, 1.0), hn::Mul(p.alpha, ev.chi_e));
    dg = hn::IfThenElse(hn::Lt(dg, C(d, 0.2)), C(d, 0.2), dg);  // alpha > 0: damp the step
    M1 = hn::IfThenElse(left, hn::Sub(M1, hn::Div(g, dg)), M1);
  }
}

// The law's lane entry (gmasim/magnetisation/jiles_atherton.hpp, JilesAthertonLaw): the
// consistent state's begin_move / joint_trial over the lanes; its state per rod is M_irr
// (kMirr). A joint trial is one evaluation of eq. (9) at (H1, M_iter) (physics::ja_evaluate,
// no inner solve): M = F(M_iter), M_irr, the slope dM/dH and 1/mu_r (ja_slope_terms), the
// law's Newton step M_next = M_iter - g / (1 - alpha chi_e) and whether |g| <= 1e-12 M_s^T.
// In the lanes where |g| > 1e-3 M_s^T (physics::ja_safeguard_residual: a poor guess) eq. (9) is
// solved at H1 (ja_solve, the scalar law's ja_step_from) from the Newton-corrected guess M_iter - g
// / max(1 - alpha chi_e, 0.2); there M_iter := M, g := 0 and the slope terms come from that
// solution's chi_e.
struct JilesAthertonLanes {
  template <class D>
  using Constants = JaLaneConstants<D>;
  template <class D>
  using Start = JaLaneStart<D>;
  // The rod's state at the step's start: H, M_irr, M and the law's last evaluation (RodState's
  // an_x, an_L, an_dL).
  template <class D>
  struct Rod {
    V<D> H, Mirr, M, an_x, an_L, an_dL;
  };
  template <class D>
  struct Trial {
    V<D> M, dM_dH, Mirr, inv_mu_r, M_next;
    V<D> an_x, an_L, an_dL;   // the evaluation the trial carries to the next step's start
    Mk<D> converged, solved;  // solved: eq. (9) solved fully (the safeguard)
  };
  template <class D>
  static Start<D> begin_move(D d, const JaLaneConstants<D>& p, const Rod<D>& r) {
    return ja_move_start(d, r.H, r.M, p, r.an_x, r.an_L, r.an_dL);
  }
  template <class D>
  static HWY_INLINE Trial<D> joint_trial(D d, const JaLaneConstants<D>& p, const Rod<D>& r,
                                         Start<D>& st, V<D> H1, V<D> M_iter) {
    Trial<D> t;
    const V<D> inv_a = p.inv_a, H0 = r.H, Mirr0 = r.Mirr, M0 = r.M;
    const Mk<D> same = hn::Eq(H1, H0);  // ja_step_from's H1 == H0: nothing moves
    V<D> chi_same = hn::Zero(d);
    if (!hn::AllFalse(d, same)) {
      V<D> L0, dL0;
      langevin_pair(d, hn::Mul(hn::Add(H0, hn::Mul(p.alpha, M0)), inv_a), L0, dL0);
      chi_same = hn::Mul(hn::Mul(hn::Mul(p.c, p.MsT), inv_a), dL0);
    }
    JaLaneEvaluation<D> e =
        ja_evaluate(d, st, H1, M_iter, p, Mirr0, inv_a, &st.near, hn::Not(same));
    // the point carried to the next step: this evaluation's (not the safeguard's last), the
    // rod's own where nothing moves (JilesAthertonLaw::joint_trial)
    t.an_x = hn::IfThenElse(same, r.an_x, e.x1);
    t.an_L = hn::IfThenElse(same, r.an_L, e.L1);
    t.an_dL = hn::IfThenElse(same, r.an_dL, e.dL1);
    V<D> g = hn::Sub(M_iter, e.M);
    const Mk<D> far = hn::AndNot(
        same, hn::Gt(hn::Abs(g), hn::Mul(C(d, physics::ja_safeguard_residual(1.0)), p.MsT)));
    t.solved = far;
    if (!hn::AllFalse(d, far)) {  // far from eq. (9): solve it there
      V<D> dg = hn::Sub(C(d, 1.0), hn::Mul(p.alpha, e.chi_e));
      dg = hn::IfThenElse(hn::Lt(dg, C(d, 0.2)), C(d, 0.2), dg);
      ja_solve(d, far, st, H1, hn::Sub(M_iter, hn::Div(g, dg)), p, Mirr0, inv_a, e);
      M_iter = hn::IfThenElse(far, e.M, M_iter);
      g = hn::IfThenElse(far, hn::Zero(d), g);
    }
    const V<D> chi = hn::IfThenElse(same, chi_same, e.chi_e);
    t.Mirr = hn::IfThenElse(same, Mirr0, e.Mirr1);
    t.M = hn::IfThenElse(same, M0, e.M);
    M_iter = hn::IfThenElse(same, M0, M_iter);
    g = hn::IfThenElse(same, hn::Zero(d), g);
    // ja_slope_terms: d = 1 - alpha chi_e, one division
    const V<D> dd = hn::Sub(C(d, 1.0), hn::Mul(p.alpha, chi)), dc = hn::Add(dd, chi);
    const V<D> inv = hn::Div(C(d, 1.0), hn::Mul(dd, dc));
    t.dM_dH = hn::Mul(hn::Mul(chi, dc), inv);
    t.inv_mu_r = hn::Mul(hn::Mul(dd, dd), inv);
    const V<D> inv_dg = hn::IfThenElse(hn::Ge(dd, C(d, 0.2)), hn::Mul(dc, inv), C(d, 5.0));
    t.M_next = hn::Sub(M_iter, hn::Mul(g, inv_dg));
    t.converged = hn::Le(hn::Abs(g), hn::Mul(C(d, 1e-12), p.MsT));
    return t;
  }
};

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // GMASIM_LANES_JA_INL_H_
