// The Preisach law (gmasim/magnetisation/preisach.hpp, physics/preisach.hpp) over SIMD lanes: the
// magnetisation-law seam's second lane entry (docs/lanes.md, "Preisach lanes"): only the adapter
// to the kernel's seam. The law itself -- the Everett function, its erfc and exp, the Newton solve
// and the trial -- is the scalar step's text (gmasim/physics/preisach_law-inl.h), instantiated
// over the lanes' number type (number_lanes-inl.h), so each lane is the scalar step bit for bit.
// Each lane's extrema stack is its own (their depths differ): the law reads it lane by lane
// (preisach_base_at) and the commit below pushes it lane by lane. Included once per target by
// src/lanes/step_lanes.cpp (hwy/foreach_target.h); it includes the kernel (step_kernel-inl.h).
#if defined(GMASIM_LANES_PREISACH_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef GMASIM_LANES_PREISACH_INL_H_
#undef GMASIM_LANES_PREISACH_INL_H_
#else
#define GMASIM_LANES_PREISACH_INL_H_
#endif

#include <cmath>

#include "gmasim/physics/preisach.hpp"
#include "hwy/highway.h"
#include "lanes/lane_data.hpp"
#include "lanes/step_kernel-inl.h"

HWY_BEFORE_NAMESPACE();
namespace gmasim::lanes::HWY_NAMESPACE {

// The law's constants of one rod over the lanes (RodConditions::preisach, MsT_mag): the
// template's own (laws::PreisachConstantsT), each a vector of the lanes' values.
template <class D>
using PreisachLaneConstants = laws::PreisachConstantsT<Lanes<D>>;

// What a trial leaves for the commit: the reduced input x1 the move ends at and the point there.
template <class D>
struct PreisachLaneTrial {
  V<D> M, dM_dH, Mirr, inv_mu_r, M_next;
  V<D> an_x, an_L, an_dL;  // the rod's own (the law does not evaluate M_an between steps)
  Mk<D> converged, solved;
  V<D> x1, mu, mc, mu_u;
  Mk<D> moved;
};

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
    // the law's trial, written once (laws::preisach_trial; the scalar PreisachLaw::trial_from)
    const laws::PreisachTrialT<Lanes<D>> p =
        laws::preisach_trial(k, r.h, Lanes<D>(r.H), Lanes<D>(r.M), Lanes<D>(H1), Lanes<D>(M_iter));
    const V<D> one = C(d, 1.0);
    Trial<D> t;
    t.moved = p.moved.m;
    t.M = p.M.v;
    t.dM_dH = p.dM_dH.v;
    t.x1 = p.x1.v;
    t.mu = p.mu.v;
    t.mc = p.mc.v;
    t.mu_u = p.mu_u.v;
    t.inv_mu_r = hn::Div(one, hn::Add(one, t.dM_dH));
    t.M_next = t.M;
    t.converged = hn::FirstN(d, hn::Lanes(d));
    t.solved = hn::FirstN(d, 0);
    // commit_trial's M_irr = M_s (1 - c)(2 mu - 1) where the move commits
    t.Mirr = hn::IfThenElse(
        t.moved,
        hn::Mul(hn::Mul(k.MsT.v, hn::Sub(one, k.c.v)), hn::Sub(hn::Mul(C(d, 2.0), t.mu), one)),
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
  k.bins.s = f(kPreSigmaU);
  for (int b = 0; b <= physics::kPreisachBins; ++b) k.bins.edge[b] = f(kPreEdge0 + b);
  for (int b = 0; b < physics::kPreisachBins; ++b) k.bins.density[b] = f(kPreDensity0 + b);
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
HWY_INLINE void commit_law_state(const typename PreisachLanes::template Start<D>&, RodStates<D>&,
                                 int) {}
template <class D>
HWY_INLINE void law_commit(const Chunk<D>& c, const PreisachLaneTrial<D>* trial, Mk<D> keep) {
  const D d = c.d;
  constexpr std::size_t W = kPad;
  const std::size_t n = hn::Lanes(d);
  double kept[W], moved[W], x1[W], mu[W], mc[W], mu_u[W];
  hn::StoreU(hn::IfThenElseZero(keep, C(d, 1.0)), d, kept);
  for (int i = 0; i < c.n; ++i) {
    const auto& tr = trial[i];
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
      physics::preisach_commit_reached(h[l], x1[l], mu[l], mc[l], mu_u[l]);
    }
  }
}

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // GMASIM_LANES_PREISACH_INL_H_
