// The Jiles-Atherton law (eq. 9) over SIMD lanes: the magnetisation-law seam's lane entry
// (docs/lanes.md, "Laws"). The law itself is gmasim/physics/laws-inl.h's (ja_joint_trial, the
// Langevin function, ...), the scalar step's own text instantiated over the lanes' number type
// (number_lanes-inl.h), so each lane equals the scalar law bit for bit; here only its adapter to
// the kernel's seam. D is any Highway tag (width 1 is the reference instance). Included once
// per target by src/lanes/step_lanes.cpp (hwy/foreach_target.h).
#if defined(GMASIM_LANES_JA_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef GMASIM_LANES_JA_INL_H_
#undef GMASIM_LANES_JA_INL_H_
#else
#define GMASIM_LANES_JA_INL_H_
#endif

#include "gmasim/physics/jiles_atherton.hpp"
#include "hwy/highway.h"
#include "lanes/number_lanes-inl.h"

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

// The Langevin function and its slope over the lanes (laws::langevin_pair: libm's exponential
// lane by lane where the closed form applies, as the scalar step's langevin_pair); the
// Preisach lanes' reversible part.
template <class D>
HWY_INLINE void langevin_pair(D, V<D> x, V<D>& L, V<D>& dL) {
  const laws::LangevinValueT<Lanes<D>> v = laws::langevin_pair(Lanes<D>(x));
  L = v.L.v;
  dL = v.dL.v;
}

// The JA constants of one rod over the lanes (RodConditions::ja, MsT_mag).
template <class D>
struct JaLaneConstants {
  V<D> MsT, a, alpha, c, k;
  V<D> inv_a;  // 1/a (RodConditions::ja_inv_a_m_per_A: LaneData kJaInvA)
  V<D> inv_k;  // 1/k (RodConditions::ja_inv_k_m_per_A: LaneData kJaInvK)
};

// The law's lane entry (gmasim/magnetisation/jiles_atherton.hpp, JilesAthertonLaw): the
// consistent state's begin_move / joint_trial over the lanes, each the scalar law's
// (laws::ja_move_start_near, laws::ja_joint_trial). Its state per rod is M_irr (kMirr) and the
// anchors of its exponentials (RodState::ja_exp: kJaLangevinY/E, kJaLagY/E), carried from step
// to step as the scalar step carries them: a move starts from the rod's anchors, a joint trial
// moves them in its live lanes only (a lane that has stopped evaluates no more, as the scalar
// solve does), and the step commits them (commit_law_state).
struct JilesAthertonLanes {
  template <class D>
  using Constants = JaLaneConstants<D>;
  template <class D>
  struct Start {
    laws::JaMoveStartT<Lanes<D>> move;
    laws::JaExpPointsT<Lanes<D>> near, recent;
  };
  // The rod's state at the step's start: H, M_irr, M, the law's last evaluation (RodState's
  // an_x, an_L, an_dL) and its anchors (ja_exp).
  template <class D>
  struct Rod {
    V<D> H, Mirr, M, an_x, an_L, an_dL;
    laws::JaExpPointsT<Lanes<D>> ja_exp;
  };
  template <class D>
  struct Trial {
    V<D> M, dM_dH, Mirr, inv_mu_r, M_next;
    V<D> an_x, an_L, an_dL;   // the evaluation the trial carries to the next step's start
    Mk<D> converged, solved;  // solved: eq. (9) solved fully (the safeguard)
  };
  template <class D>
  static laws::JaCoefficientsT<Lanes<D>> coefficients(const JaLaneConstants<D>& p) {
    return {p.a, p.alpha, p.c, p.k};
  }
  template <class D>
  static Start<D> begin_move(D, const JaLaneConstants<D>& p, const Rod<D>& r) {
    using N = Lanes<D>;
    return {laws::ja_move_start_near<N>(r.H, r.M, p.MsT, coefficients(p), p.inv_a, p.inv_k, r.an_x,
                                        {r.an_L, r.an_dL}),
            r.ja_exp, laws::no_ja_exp_points<N>()};
  }
  template <class D>
  static HWY_INLINE Trial<D> joint_trial(D, const JaLaneConstants<D>& p, const Rod<D>& r,
                                         Start<D>& st, V<D> H1, V<D> M_iter, Mk<D> live) {
    using N = Lanes<D>;
    const laws::JaJointTrialT<N> j =
        laws::ja_joint_trial<N>(r.H, r.Mirr, r.M, r.an_x, {r.an_L, r.an_dL}, p.MsT, coefficients(p),
                                st.move, st.near, st.recent, H1, M_iter, LaneMask<D>{live});
    return {j.M.v,    j.dM_dH.v,   j.Mirr.v,     j.inv_mu_r.v,  j.M_next.v,
            j.an_x.v, j.an_lv.L.v, j.an_lv.dL.v, j.converged.m, j.solved.m};
  }
};

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // GMASIM_LANES_JA_INL_H_
