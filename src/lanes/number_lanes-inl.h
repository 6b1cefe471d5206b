// The lanes' number type (gmasim/physics/number.hpp): Lanes<D> holds one Highway vector of D, a
// lane per simulation, with the operators and primitives the step's laws are written with, so
// that the laws of gmasim/physics instantiate over it. Each operation is the IEEE operation of
// the scalar instance, lane by lane (no contraction: the lanes are built with -ffp-contract=off);
// each() applies the scalar function itself lane by lane. A lane therefore equals the scalar
// instance bit for bit. Included once per target (hwy/foreach_target.h).
#if defined(GMASIM_LANES_NUMBER_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef GMASIM_LANES_NUMBER_INL_H_
#undef GMASIM_LANES_NUMBER_INL_H_
#else
#define GMASIM_LANES_NUMBER_INL_H_
#endif

#include <cstddef>

#include "gmasim/physics/laws.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace gmasim::lanes::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

// A comparison's result over the lanes.
template <class D>
struct LaneMask {
  hn::Mask<D> m;
  friend HWY_INLINE LaneMask operator&&(LaneMask a, LaneMask b) { return {hn::And(a.m, b.m)}; }
  friend HWY_INLINE LaneMask operator||(LaneMask a, LaneMask b) { return {hn::Or(a.m, b.m)}; }
  friend HWY_INLINE LaneMask operator!(LaneMask a) { return {hn::Not(a.m)}; }
  friend HWY_INLINE bool any(LaneMask a) { return !hn::AllFalse(D(), a.m); }
  friend HWY_INLINE bool all(LaneMask a) { return hn::AllTrue(D(), a.m); }
  friend HWY_INLINE bool none(LaneMask a) { return hn::AllFalse(D(), a.m); }
};

// W numbers, one per lane. A double converts to every lane's copy of it (the laws' constants).
template <class D>
struct Lanes {
  using V = hn::Vec<D>;
  using M = LaneMask<D>;
  V v;
  HWY_INLINE Lanes() = default;
  HWY_INLINE Lanes(V x) : v(x) {}                     // NOLINT: implicit by design
  HWY_INLINE Lanes(double x) : v(hn::Set(D(), x)) {}  // NOLINT: implicit by design
  friend HWY_INLINE Lanes operator+(Lanes a, Lanes b) { return hn::Add(a.v, b.v); }
  friend HWY_INLINE Lanes operator-(Lanes a, Lanes b) { return hn::Sub(a.v, b.v); }
  friend HWY_INLINE Lanes operator*(Lanes a, Lanes b) { return hn::Mul(a.v, b.v); }
  friend HWY_INLINE Lanes operator/(Lanes a, Lanes b) { return hn::Div(a.v, b.v); }
  friend HWY_INLINE Lanes operator-(Lanes a) { return hn::Neg(a.v); }
  friend HWY_INLINE M operator<(Lanes a, Lanes b) { return {hn::Lt(a.v, b.v)}; }
  friend HWY_INLINE M operator<=(Lanes a, Lanes b) { return {hn::Le(a.v, b.v)}; }
  friend HWY_INLINE M operator>(Lanes a, Lanes b) { return {hn::Gt(a.v, b.v)}; }
  friend HWY_INLINE M operator>=(Lanes a, Lanes b) { return {hn::Ge(a.v, b.v)}; }
  friend HWY_INLINE M operator==(Lanes a, Lanes b) { return {hn::Eq(a.v, b.v)}; }
  friend HWY_INLINE Lanes select(M m, Lanes a, Lanes b) { return hn::IfThenElse(m.m, a.v, b.v); }
  friend HWY_INLINE M true_mask(Lanes) { return {hn::FirstN(D(), hn::Lanes(D()))}; }
  friend HWY_INLINE Lanes abs(Lanes a) { return hn::Abs(a.v); }
  friend HWY_INLINE Lanes sqrt(Lanes a) { return hn::Sqrt(a.v); }
  friend HWY_INLINE Lanes table_at(const double* t, Lanes j) {
    const hn::RebindToSigned<D> di;
    return hn::GatherIndex(D(), t, hn::ConvertTo(di, j.v));
  }
  // 2^n for integers n in [-1022, 1023]: the exponent field n + 1023 over a zero mantissa.
  friend HWY_INLINE Lanes pow2i(Lanes n) {
    const hn::RebindToSigned<D> di;
    const auto e = hn::Add(hn::ConvertTo(di, n.v), hn::Set(di, 1023));
    return hn::BitCast(D(), hn::ShiftLeft<52>(e));
  }
  // The scalar function f in each lane where m holds, x kept elsewhere (libm: the scalar step's
  // own algorithm).
  template <class F>
  friend HWY_INLINE Lanes each(F f, Lanes x, M m) {
    constexpr std::size_t kMax = hn::MaxLanes(D());
    HWY_ALIGN double a[kMax], w[kMax];
    const D d;
    hn::Store(x.v, d, a);
    hn::Store(hn::VecFromMask(d, m.m), d, w);
    for (std::size_t i = 0; i < hn::Lanes(d); ++i)
      if (w[i] != 0.0) a[i] = f(a[i]);
    return hn::Load(d, a);
  }
};

// physics::oscillator_free_closed_form in the lanes of `where` (the rare path: beyond the
// propagator's series), lane by lane: the scalar function itself.
template <class D>
HWY_NOINLINE void oscillator_free_closed_form_where(LaneMask<D> where, Lanes<D> m, Lanes<D> c,
                                                    Lanes<D> k, Lanes<D> h, Lanes<D> e0,
                                                    Lanes<D> ed0, Lanes<D>& e1, Lanes<D>& ed1) {
  constexpr std::size_t kMax = hn::MaxLanes(D());
  HWY_ALIGN double w[kMax], am[kMax], ac[kMax], ak[kMax], ah[kMax], a0[kMax], ad0[kMax], a1[kMax],
      ad1[kMax];
  const D d;
  hn::Store(hn::VecFromMask(d, where.m), d, w);
  hn::Store(m.v, d, am);
  hn::Store(c.v, d, ac);
  hn::Store(k.v, d, ak);
  hn::Store(h.v, d, ah);
  hn::Store(e0.v, d, a0);
  hn::Store(ed0.v, d, ad0);
  hn::Store(e1.v, d, a1);
  hn::Store(ed1.v, d, ad1);
  for (std::size_t i = 0; i < hn::Lanes(d); ++i)
    if (w[i] != 0.0)
      physics::oscillator_free_closed_form(am[i], ac[i], ak[i], ah[i], a0[i], ad0[i], a1[i],
                                           ad1[i]);
  e1 = hn::Load(d, a1);
  ed1 = hn::Load(d, ad1);
}

// The Preisach law's stack read at x, lane by lane (physics::preisach_base on each lane's own
// stack: the stacks differ in depth from lane to lane), as the scalar overload
// (gmasim/physics/laws.hpp) reads its one stack.
template <class D>
HWY_NOINLINE void preisach_base_at(const physics::PreisachHistory* h, Lanes<D> x, Lanes<D>& xb,
                                   Lanes<D>& mub, Lanes<D>& mcb, Lanes<D>& mub_u, LaneMask<D>& up,
                                   LaneMask<D>& same) {
  constexpr std::size_t kMax = hn::MaxLanes(D());
  HWY_ALIGN double xs[kMax], b_x[kMax], b_mu[kMax], b_mc[kMax], b_mu_u[kMax], b_up[kMax],
      b_same[kMax];
  const D d;
  hn::Store(x.v, d, xs);
  for (std::size_t l = 0; l < hn::Lanes(d); ++l) {
    const physics::PreisachBase b = physics::preisach_base(h[l], xs[l]);
    b_x[l] = b.xb;
    b_mu[l] = b.mub;
    b_mc[l] = b.mcb;
    b_mu_u[l] = b.mub_u;
    b_up[l] = b.up ? 1.0 : 0.0;
    b_same[l] = b.same ? 1.0 : 0.0;
  }
  xb = hn::Load(d, b_x);
  mub = hn::Load(d, b_mu);
  mcb = hn::Load(d, b_mc);
  mub_u = hn::Load(d, b_mu_u);
  up = {hn::Ne(hn::Load(d, b_up), hn::Zero(d))};
  same = {hn::Ne(hn::Load(d, b_same), hn::Zero(d))};
}

// The step's laws (gmasim/physics/laws-inl.h), the same text as the scalar step's, compiled for
// this target: physics laws over Lanes<D> (rod_mechanics, oscillator_step, ...), and the
// consistent state's joint Newton solve and commit (joint_newton-inl.h) and the mechanical
// stages (mechanics_stage-inl.h).
namespace laws {
using ::gmasim::lanes::HWY_NAMESPACE::oscillator_free_closed_form_where;
using ::gmasim::lanes::HWY_NAMESPACE::preisach_base_at;
#define GMASIM_LAW_INLINE HWY_INLINE
#define GMASIM_LAW_RARE HWY_NOINLINE
#include "gmasim/physics/laws-inl.h"  // NOLINT(build/include): once per target, by design
// after laws-inl.h, whose series and anchors it uses (a block of its own: clang-format keeps it)
#include "gmasim/physics/ja_law-inl.h"  // NOLINT(build/include): likewise
// after ja_law-inl.h, whose langevin_pair it uses
#include "gmasim/physics/preisach_law-inl.h"  // NOLINT(build/include): likewise
// the consistent state's solve and commit (the scalar step's: gmasim/physics/stages.hpp)
#include "gmasim/physics/joint_newton-inl.h"  // NOLINT(build/include): likewise
// the rods' circuit system (the scalar netlist's low-rank solve)
#include "gmasim/physics/rod_circuit-inl.h"  // NOLINT(build/include): likewise
// the mechanical stages (the scalar step's: gmasim/physics/stages.hpp)
#include "gmasim/physics/mechanics_stage-inl.h"  // NOLINT(build/include): likewise
// the stages' order (the scalar step's)
#include "gmasim/physics/stage_order-inl.h"  // NOLINT(build/include): likewise
#undef GMASIM_LAW_INLINE
#undef GMASIM_LAW_RARE
}  // namespace laws

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // GMASIM_LANES_NUMBER_INL_H_
