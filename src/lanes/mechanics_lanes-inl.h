// The mechanical laws over SIMD lanes (eq. 11-18): one function per law of
// gmasim/physics/magnetostriction.hpp and mechanics.hpp, operation for operation the scalar
// code, branches replaced by per-lane selects. Included once per target by
// src/lanes/step_lanes.cpp (hwy/foreach_target.h).
#if defined(GMASIM_LANES_MECHANICS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef GMASIM_LANES_MECHANICS_INL_H_
#undef GMASIM_LANES_MECHANICS_INL_H_
#else
#define GMASIM_LANES_MECHANICS_INL_H_
#endif

#include "gmasim/physics/oscillator.hpp"
#include "hwy/contrib/math/math-inl.h"
#include "hwy/highway.h"
#include "lanes/ja_lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace gmasim::lanes::HWY_NAMESPACE {

// cos(pi m / 2) where |m| <= 1 by its Taylor series in t = m^2 to t^10 (truncation below 2e-17
// absolute, no range reduction), hn::Cos where a lane is beyond (computed only then).
template <class D>
HWY_INLINE V<D> cos_half_pi(D d, V<D> m) {
  const V<D> t = hn::Mul(m, m), t2 = hn::Mul(t, t), t4 = hn::Mul(t2, t2), t8 = hn::Mul(t4, t4);
  auto pair = [&](double a, double b) { return hn::Sub(C(d, a), hn::Mul(C(d, b), t)); };
  const V<D> series = hn::Add(
      hn::Add(
          hn::Add(pair(1.0, 1.2337005501361697),
                  hn::Mul(t2, pair(0.25366950790104803, 0.02086348076335296))),
          hn::Mul(t4, hn::Add(pair(0.0009192602748394266, 2.5202042373060607e-05),
                              hn::Mul(t2, pair(4.710874778818172e-07, 6.386603083791852e-09))))),
      hn::Mul(t8, hn::Add(pair(6.565963114979473e-11, 5.294400200734623e-13),
                          hn::Mul(t2, C(d, 3.437739179098607e-15)))));
  const Mk<D> in = hn::Le(hn::Abs(m), C(d, 1.0));
  if (hn::AllTrue(d, in)) return series;
  return hn::IfThenElse(in, series, hn::Cos(d, hn::Mul(C(d, 1.5707963267948966), m)));
}

// Eq. (13): the Delta-E compliance 1/E at m = M/M_s^T (magnetostriction.hpp,
// delta_e_compliance), its last term multiplied through by cos^2(pi m/2) (cos_half_pi: the
// scalar's std::cos to a few 1e-16 absolute).
template <class D>
HWY_INLINE V<D> delta_e_compliance(D d, V<D> m, V<D> inv_Es, V<D> rot, V<D> coupling, V<D> mu0Ms2,
                                   V<D> S) {
  const V<D> c = cos_half_pi(d, m);
  const V<D> c2 = hn::Mul(c, c);
  const V<D> m2 = hn::Mul(m, m);
  const V<D> third = hn::Div(hn::Mul(hn::Mul(hn::Mul(coupling, coupling), m2), c2),
                             hn::Sub(mu0Ms2, hn::Mul(c2, S)));
  return hn::Add(hn::Add(inv_Es, hn::Mul(rot, hn::Sub(C(d, 1.0), m2))), third);
}

// Eq. (11)-(12): lambda = f(sigma_p) lambda_s m^2 with the prestress factor f at the
// thresholds sigma_s = lambda_s E / 2, sigma_max = 3 lambda_s E / 2 (magnetostriction.hpp,
// prestress_factor_at), its tanh from one exponential (tanh_absolute); u = 2 sigma_p / sigma_s,
// given as (4 sigma_p / lambda_s) / E. The factor above sigma_s only where a lane needs it.
template <class D>
HWY_INLINE V<D> magnetostriction(D d, V<D> m, V<D> lambda_s, V<D> sigma_p, V<D> E, V<D> u) {
  const V<D> ss = hn::Mul(hn::Mul(C(d, 0.5), lambda_s), E);
  const V<D> e = hn::Exp(d, hn::Mul(C(d, -2.0), hn::Abs(u)));
  const V<D> ta = hn::Div(hn::Sub(C(d, 1.0), e), hn::Add(C(d, 1.0), e));
  const V<D> t = hn::IfThenElse(hn::Lt(u, hn::Zero(d)), hn::Neg(ta), ta);
  const V<D> base = hn::Add(C(d, 1.0), hn::Mul(C(d, 0.5), t));
  const Mk<D> below = hn::Le(sigma_p, ss);
  V<D> f = base;
  if (!hn::AllTrue(d, below)) {
    const V<D> smax = hn::Mul(hn::Mul(C(d, 1.5), lambda_s), E);
    const V<D> above = hn::Mul(hn::Sub(C(d, 1.0), hn::Div(hn::Sub(sigma_p, ss), smax)), base);
    f = hn::IfThenElse(below, base, above);
  }
  return hn::Mul(hn::Mul(hn::Mul(f, lambda_s), m), m);
}

// The closed form of the free row m e'' + c e' + k e = 0 over h (oscillator.hpp,
// oscillator_free_closed_form): under-, over- or critically damped per lane, each regime
// computed only where a lane is in it. Out of line: the rare path (beyond the series'
// caps: over-damped |u| > 4, under-damped w_d h > 256), so that oscillator_step's common one stays
// small in the inlined kernel.
template <class D>
HWY_NOINLINE void oscillator_closed_form(D d, V<D> m, V<D> c, V<D> k, V<D> h, V<D> e0, V<D> ed0,
                                         V<D>& e1, V<D>& ed1) {
  const V<D> wn = hn::Sqrt(hn::Div(k, m));
  const V<D> zeta = hn::Div(c, hn::Mul(C(d, 2.0), hn::Sqrt(hn::Mul(k, m))));
  const Mk<D> under = hn::Lt(zeta, C(d, 1.0 - 1e-9)), over = hn::Gt(zeta, C(d, 1.0 + 1e-9));
  e1 = ed1 = hn::Zero(d);
  if (!hn::AllFalse(d, under)) {
    const V<D> zwn = hn::Mul(zeta, wn);
    const V<D> wd = hn::Mul(wn, hn::Sqrt(hn::Sub(C(d, 1.0), hn::Mul(zeta, zeta))));
    const V<D> decay = hn::Exp(d, hn::Mul(hn::Mul(hn::Neg(zeta), wn), h));
    const V<D> cs = hn::Cos(d, hn::Mul(wd, h)), sn = hn::Sin(d, hn::Mul(wd, h));
    const V<D> B = hn::Div(hn::Add(ed0, hn::Mul(zwn, e0)), wd);
    e1 = hn::Mul(decay, hn::Add(hn::Mul(e0, cs), hn::Mul(B, sn)));
    ed1 = hn::Mul(
        decay,
        hn::Sub(
            hn::Mul(ed0, cs),
            hn::Mul(hn::Div(hn::Add(hn::Mul(hn::Mul(wn, wn), e0), hn::Mul(zwn, ed0)), wd), sn)));
    if (hn::AllTrue(d, under)) return;
  }
  if (!hn::AllFalse(d, over)) {
    const V<D> s = hn::Mul(wn, hn::Sqrt(hn::Sub(hn::Mul(zeta, zeta), C(d, 1.0))));
    const V<D> nzwn = hn::Mul(hn::Neg(zeta), wn);
    const V<D> r1 = hn::Add(nzwn, s), r2 = hn::Sub(nzwn, s);
    const V<D> A1 = hn::Div(hn::Sub(ed0, hn::Mul(r2, e0)), hn::Sub(r1, r2));
    const V<D> A2 = hn::Div(hn::Sub(hn::Mul(r1, e0), ed0), hn::Sub(r1, r2));
    const V<D> E1 = hn::Exp(d, hn::Mul(r1, h)), E2 = hn::Exp(d, hn::Mul(r2, h));
    e1 = hn::IfThenElse(over, hn::Add(hn::Mul(A1, E1), hn::Mul(A2, E2)), e1);
    ed1 = hn::IfThenElse(over, hn::Add(hn::Mul(hn::Mul(A1, r1), E1), hn::Mul(hn::Mul(A2, r2), E2)),
                         ed1);
  }
  const Mk<D> critical = hn::Not(hn::Or(under, over));
  if (!hn::AllFalse(d, critical)) {
    const V<D> Ec = hn::Exp(d, hn::Mul(hn::Neg(wn), h));
    const V<D> Bc = hn::Add(ed0, hn::Mul(wn, e0));
    const V<D> eBh = hn::Add(e0, hn::Mul(Bc, h));
    e1 = hn::IfThenElse(critical, hn::Mul(eBh, Ec), e1);
    ed1 = hn::IfThenElse(critical, hn::Mul(hn::Sub(Bc, hn::Mul(wn, eBh)), Ec), ed1);
  }
}

// oscillator.hpp's oscillator_series_doubled per lane: (C, S) of exp(N / 2) to those of exp(N),
// in the lanes of `where`.
template <class D>
HWY_INLINE void oscillator_series_doubled(D, V<D> u_half, Mk<D> where, V<D>& C, V<D>& S) {
  const V<D> C2 = hn::Add(hn::Mul(C, C), hn::Mul(u_half, hn::Mul(S, S)));
  const V<D> S2 = hn::Mul(C, S);
  C = hn::IfThenElse(where, C2, C);
  S = hn::IfThenElse(where, S2, S);
}

// The propagator's series of a long step (oscillator.hpp, oscillator_propagator where 4 < |u| <=
// kOscillatorSeriesUnder, under-damped) in the lanes of `where`: C and S summed at u / 4^n and
// doubled n times, n each lane's fewest halvings to |u| <= 1/4 (as many passes as the most of
// them). Out of line: the rare path (steps longer than a third of the row's period: the
// identification's low frequencies at 200 steps a period).
template <class D>
HWY_NOINLINE void oscillator_series_long(D d, V<D> u, Mk<D> where, V<D>& Cu, V<D>& Su) {
  V<D> us = u, level = hn::Zero(d);
  Mk<D> more = where;
  int halvings = 0;
  for (; !hn::AllFalse(d, more); ++halvings) {
    us = hn::IfThenElse(more, hn::Mul(C(d, 0.25), us), us);
    level = hn::IfThenElse(more, hn::Add(level, C(d, 1.0)), level);
    more = hn::And(more, hn::Gt(hn::Abs(us), C(d, 0.25)));
  }
  V<D> Cl = polynomial7(d, us, physics::kOscillatorCos);
  V<D> Sl = polynomial7(d, us, physics::kOscillatorSinc);
  V<D> u_half = us;  // (N / 2^j)^2 = u / 4^j, in the lanes with j halvings or more
  for (int j = halvings; j >= 1; --j) {
    const Mk<D> at = hn::Ge(level, C(d, static_cast<double>(j)));
    oscillator_series_doubled(d, u_half, at, Cl, Sl);
    u_half = hn::IfThenElse(at, hn::Mul(C(d, 4.0), u_half), u_half);
  }
  Cu = hn::IfThenElse(where, Cl, Cu);
  Su = hn::IfThenElse(where, Sl, Su);
}

// Eq. (15), one diagonal row m x'' + c x' + k x = F(t) with F linear over the step, exact
// (mechanics.hpp, oscillator_step; inv_m = 1/m): the free row by the series of its propagator
// (oscillator_propagator: f0 = e^(tau/2) (C - tau/2 S), f1 = e^(tau/2) S, C and S summed in u =
// tau^2/4 - delta -- at u / 4 and doubled once where 1/4 < |u| <= 1, at u / 16 and doubled twice
// where 1 < |u| <= 4, each only where a lane needs it; under-damped beyond, to
// kOscillatorSeriesUnder, at u / 4^n doubled n times (oscillator_series_long) -- e^(tau/2) by its
// series where |tau/2| <= 1/64), by the closed form in the lanes beyond (oscillator_closed_form,
// only where a lane needs it).
template <class D>
HWY_INLINE void oscillator_step(D d, V<D> m, V<D> inv_m, V<D> c, V<D> k, V<D> F0, V<D> F1, V<D> h,
                                V<D>& x, V<D>& v) {
  const V<D> g = hn::Div(hn::Sub(F1, F0), h);  // force rate [N/s]
  const V<D> inv_k = hn::Div(C(d, 1.0), k);
  const V<D> gck = hn::Mul(hn::Mul(g, c), inv_k);
  const V<D> xp0 = hn::Mul(hn::Sub(F0, gck), inv_k);
  const V<D> vp = hn::Mul(g, inv_k);
  const V<D> e0 = hn::Sub(x, xp0), ed0 = hn::Sub(v, vp);
  const V<D> c_m = hn::Mul(c, inv_m), k_m = hn::Mul(k, inv_m);
  const V<D> half_tau = hn::Mul(C(d, 0.5), hn::Mul(hn::Neg(c_m), h));
  const V<D> u = hn::Sub(hn::Mul(half_tau, half_tau), hn::Mul(hn::Mul(k_m, h), h));
  const V<D> au = hn::Abs(u);
  // the series where |u| <= 4 (halved at most twice), and where under-damped (u < 0) to
  // kOscillatorSeriesUnder (oscillator_series_long)
  const Mk<D> long_step = hn::AndNot(
      hn::Le(au, C(d, 4.0)),
      hn::And(hn::Lt(u, hn::Zero(d)), hn::Le(au, C(d, physics::kOscillatorSeriesUnder))));
  const Mk<D> series = hn::Or(hn::Le(au, C(d, 4.0)), long_step);
  V<D> e1 = hn::Zero(d), ed1 = hn::Zero(d);
  if (!hn::AllFalse(d, series)) {  // the propagator's series, where a lane's step is short
    const Mk<D> once = hn::Gt(au, C(d, 0.25)), twice = hn::Gt(au, C(d, 1.0));
    const bool halved = !hn::AllFalse(d, once), halved_twice = !hn::AllFalse(d, twice);
    V<D> us = u;
    if (halved) {
      const V<D> u4 = hn::Mul(C(d, 0.25), u), u16 = hn::Mul(C(d, 0.0625), u);
      us = hn::IfThenElse(twice, u16, hn::IfThenElse(once, u4, u));
    }
    V<D> Cu = polynomial7(d, us, physics::kOscillatorCos);
    V<D> Su = polynomial7(d, us, physics::kOscillatorSinc);
    if (halved_twice) oscillator_series_doubled(d, hn::Mul(C(d, 0.0625), u), twice, Cu, Su);
    if (halved) oscillator_series_doubled(d, hn::Mul(C(d, 0.25), u), once, Cu, Su);
    if (!hn::AllFalse(d, long_step)) oscillator_series_long(d, u, long_step, Cu, Su);
    const Mk<D> short_tau = hn::Le(hn::Abs(half_tau), C(d, 1.0 / 64));
    V<D> E = exp_series7(d, half_tau);
    if (!hn::AllTrue(d, short_tau)) E = hn::IfThenElse(short_tau, E, hn::Exp(d, half_tau));
    const V<D> f0 = hn::Mul(E, hn::Sub(Cu, hn::Mul(half_tau, Su)));
    const V<D> f1h = hn::Mul(hn::Mul(E, Su), h);
    e1 = hn::Add(hn::Mul(f0, e0), hn::Mul(f1h, ed0));
    ed1 = hn::Sub(hn::Mul(f0, ed0), hn::Mul(f1h, hn::Add(hn::Mul(k_m, e0), hn::Mul(c_m, ed0))));
  }
  if (!hn::AllTrue(d, series)) {
    V<D> e1c, ed1c;
    oscillator_closed_form(d, m, c, k, h, e0, ed0, e1c, ed1c);
    e1 = hn::IfThenElse(series, e1, e1c);
    ed1 = hn::IfThenElse(series, ed1, ed1c);
  }
  const V<D> xp1 = hn::Mul(hn::Sub(F1, gck), inv_k);
  x = hn::Add(xp1, e1);
  v = hn::Add(vp, ed1);
}

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // GMASIM_LANES_MECHANICS_INL_H_
