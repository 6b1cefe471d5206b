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

#include "hwy/contrib/math/math-inl.h"
#include "hwy/highway.h"
#include "lanes/ja_lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace gmasim::lanes::HWY_NAMESPACE {

// Eq. (13): the Delta-E modulus at m = M/M_s^T (magnetostriction.hpp, delta_e_modulus), its
// last term multiplied through by cos^2(pi m/2).
template <class D>
HWY_INLINE V<D> delta_e_modulus(D d, V<D> m, V<D> inv_Es, V<D> rot, V<D> coupling, V<D> mu0Ms2,
                                V<D> S) {
  const V<D> c = hn::Cos(d, hn::Mul(C(d, 0.5 * 3.14159265358979323846), m));
  const V<D> c2 = hn::Mul(c, c);
  const V<D> m2 = hn::Mul(m, m);
  const V<D> third = hn::Div(hn::Mul(hn::Mul(hn::Mul(coupling, coupling), m2), c2),
                             hn::Sub(mu0Ms2, hn::Mul(c2, S)));
  return hn::Div(C(d, 1.0), hn::Add(hn::Add(inv_Es, hn::Mul(rot, hn::Sub(C(d, 1.0), m2))), third));
}

// Eq. (11)-(12): lambda = f(sigma_p) lambda_s m^2 with the prestress factor f at the
// thresholds sigma_s = lambda_s E / 2, sigma_max = 3 lambda_s E / 2 (magnetostriction.hpp).
template <class D>
HWY_INLINE V<D> magnetostriction(D d, V<D> m, V<D> lambda_s, V<D> sigma_p, V<D> E) {
  const V<D> ss = hn::Mul(hn::Mul(C(d, 0.5), lambda_s), E);
  const V<D> smax = hn::Mul(hn::Mul(C(d, 1.5), lambda_s), E);
  const V<D> base =
      hn::Add(C(d, 1.0), hn::Mul(C(d, 0.5), hn::Tanh(d, hn::Div(hn::Mul(C(d, 2.0), sigma_p), ss))));
  const V<D> above = hn::Mul(hn::Sub(C(d, 1.0), hn::Div(hn::Sub(sigma_p, ss), smax)), base);
  const V<D> f = hn::IfThenElse(hn::Le(sigma_p, ss), base, above);
  return hn::Mul(hn::Mul(hn::Mul(f, lambda_s), m), m);
}

// Eq. (15), one diagonal row m x'' + c x' + k x = F(t) with F linear over the step, exact
// (mechanics.hpp, oscillator_step): under-, over- or critically damped per lane.
template <class D>
HWY_INLINE void oscillator_step(D d, V<D> m, V<D> c, V<D> k, V<D> F0, V<D> F1, V<D> h, V<D>& x,
                                V<D>& v) {
  const V<D> g = hn::Div(hn::Sub(F1, F0), h);
  const V<D> gck = hn::Div(hn::Mul(g, c), k);
  const V<D> xp0 = hn::Div(hn::Sub(F0, gck), k);
  const V<D> vp = hn::Div(g, k);
  const V<D> e0 = hn::Sub(x, xp0), ed0 = hn::Sub(v, vp);
  const V<D> wn = hn::Sqrt(hn::Div(k, m));
  const V<D> zeta = hn::Div(c, hn::Mul(C(d, 2.0), hn::Sqrt(hn::Mul(k, m))));
  const V<D> zwn = hn::Mul(zeta, wn);
  // under-damped
  const V<D> wd = hn::Mul(wn, hn::Sqrt(hn::Sub(C(d, 1.0), hn::Mul(zeta, zeta))));
  const V<D> decay = hn::Exp(d, hn::Mul(hn::Mul(hn::Neg(zeta), wn), h));
  const V<D> cs = hn::Cos(d, hn::Mul(wd, h)), sn = hn::Sin(d, hn::Mul(wd, h));
  const V<D> B = hn::Div(hn::Add(ed0, hn::Mul(zwn, e0)), wd);
  const V<D> e1u = hn::Mul(decay, hn::Add(hn::Mul(e0, cs), hn::Mul(B, sn)));
  const V<D> ed1u = hn::Mul(
      decay,
      hn::Sub(hn::Mul(ed0, cs),
              hn::Mul(hn::Div(hn::Add(hn::Mul(hn::Mul(wn, wn), e0), hn::Mul(zwn, ed0)), wd), sn)));
  const Mk<D> under = hn::Lt(zeta, C(d, 1.0 - 1e-9));
  V<D> e1 = e1u, ed1 = ed1u;
  if (!hn::AllTrue(d, under)) {  // the other regimes only where a lane needs them
    // over-damped
    const V<D> s = hn::Mul(wn, hn::Sqrt(hn::Sub(hn::Mul(zeta, zeta), C(d, 1.0))));
    const V<D> nzwn = hn::Mul(hn::Neg(zeta), wn);
    const V<D> r1 = hn::Add(nzwn, s), r2 = hn::Sub(nzwn, s);
    const V<D> A1 = hn::Div(hn::Sub(ed0, hn::Mul(r2, e0)), hn::Sub(r1, r2));
    const V<D> A2 = hn::Div(hn::Sub(hn::Mul(r1, e0), ed0), hn::Sub(r1, r2));
    const V<D> E1 = hn::Exp(d, hn::Mul(r1, h)), E2 = hn::Exp(d, hn::Mul(r2, h));
    const V<D> e1o = hn::Add(hn::Mul(A1, E1), hn::Mul(A2, E2));
    const V<D> ed1o = hn::Add(hn::Mul(hn::Mul(A1, r1), E1), hn::Mul(hn::Mul(A2, r2), E2));
    // critically damped
    const V<D> Ec = hn::Exp(d, hn::Mul(hn::Neg(wn), h));
    const V<D> Bc = hn::Add(ed0, hn::Mul(wn, e0));
    const V<D> eBh = hn::Add(e0, hn::Mul(Bc, h));
    const V<D> e1c = hn::Mul(eBh, Ec);
    const V<D> ed1c = hn::Mul(hn::Sub(Bc, hn::Mul(wn, eBh)), Ec);
    const Mk<D> over = hn::Gt(zeta, C(d, 1.0 + 1e-9));
    e1 = hn::IfThenElse(under, e1u, hn::IfThenElse(over, e1o, e1c));
    ed1 = hn::IfThenElse(under, ed1u, hn::IfThenElse(over, ed1o, ed1c));
  }
  const V<D> xp1 = hn::Div(hn::Sub(F1, gck), k);
  x = hn::Add(xp1, e1);
  v = hn::Add(vp, ed1);
}

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // GMASIM_LANES_MECHANICS_INL_H_
