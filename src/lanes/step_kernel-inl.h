// The consistent step over SIMD lanes (docs/lanes.md): model/step.cpp's step_law for W
// simulations at once, in the same stages -- the consistent magnetic state (the scalar step's
// own text, gmasim/physics/joint_newton-inl.h, run with the lanes' context LaneNewton), the
// mechanics (eq. 11-18), the sensor mount, the outputs -- and with the same checks (step() and
// run_loop()), recorded per lane instead of thrown. Included once per target by
// src/lanes/step_lanes.cpp (hwy/foreach_target.h).
#if defined(GMASIM_LANES_STEP_KERNEL_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef GMASIM_LANES_STEP_KERNEL_INL_H_
#undef GMASIM_LANES_STEP_KERNEL_INL_H_
#else
#define GMASIM_LANES_STEP_KERNEL_INL_H_
#endif

#include "gmasim/model/validity.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/magnetostriction.hpp"
#include "gmasim/physics/mechanics.hpp"
#include "hwy/highway.h"
#include "lanes/ja_lanes-inl.h"
#include "lanes/lane_data.hpp"
#include "lanes/number_lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace gmasim::lanes::HWY_NAMESPACE {

// W lanes of the LaneData from lane j: loads, and the per-lane failure record. The addresses
// of lane j's rod, global and circuit fields (LaneData::rod, glob, S, bt_coil, bt_pm) from
// their bases and stride held here: read through L, they were reloaded after every vector
// store (which may alias L) -- a tenth of the kernel's instructions.
template <class D>
struct Chunk {
  D d;
  LaneData& L;
  std::size_t j;
  int n;  // rods
  double *rb, *gb, *cb;
  std::size_t np;  // LaneData::npad
  Chunk(D d_, LaneData& L_, std::size_t j_)
      : d(d_),
        L(L_),
        j(j_),
        n(L_.st.rods),
        rb(L_.r.data() + j_),
        gb(L_.g.data() + j_),
        cb(L_.cm.data() + j_),
        np(L_.npad) {}
  double* rod_at(int f, int i) const {
    return rb + (static_cast<std::size_t>(f) * kMaxRods + static_cast<std::size_t>(i)) * np;
  }
  double* glob_at(int f) const { return gb + static_cast<std::size_t>(f) * np; }
  double* S_at(int a, int b) const { return cb + static_cast<std::size_t>(a * kMaxRods + b) * np; }
  double* bt_coil_at(int a) const {
    return cb + static_cast<std::size_t>(kMaxRods * kMaxRods + a) * np;
  }
  double* bt_pm_at(int a) const {
    return cb + static_cast<std::size_t>(kMaxRods * kMaxRods + kMaxRods + a) * np;
  }
  V<D> rod(int f, int i) const { return hn::LoadU(d, rod_at(f, i)); }
  V<D> glob(int f) const { return hn::LoadU(d, glob_at(f)); }
};

// The first failure of each lane in this step: code, value, rod and time (kFail...).
template <class D>
struct Fails {
  Mk<D> failed;
  V<D> code, value, rod, t, bound;
  void mark(D d, Mk<D> m, FailCode c, V<D> val, int rod_index, V<D> time, V<D> limit) {
    const Mk<D> nw = hn::AndNot(failed, m);
    if (hn::AllFalse(d, nw)) return;  // the common case: no new failure
    bound = hn::IfThenElse(nw, limit, bound);
    code = hn::IfThenElse(nw, hn::Set(d, static_cast<double>(c)), code);
    value = hn::IfThenElse(nw, val, value);
    rod = hn::IfThenElse(nw, hn::Set(d, static_cast<double>(rod_index)), rod);
    t = hn::IfThenElse(nw, time, t);
    failed = hn::Or(failed, nw);
  }
  // step()'s check(): |value| <= limit, false for NaN.
  void check(D d, V<D> v, V<D> limit, FailCode c, int rod_index, V<D> time) {
    mark(d, hn::Not(hn::Le(hn::Abs(v), limit)), c, v, rod_index, time, limit);
  }
};

// The rods' state over the lanes (RodState's numbers, kH .. kB).
template <class D>
struct RodStates {
  V<D> f[kRodStateCount][kMaxRods];
};

// The rods' circuit system per lane (circuit/netlist.cpp's low-rank solve: the one text of
// gmasim/physics/rod_circuit-inl.h): the lane's S = B^T G0^-1 B and B^T psi_coil, B^T psi_pm
// (LaneData's circuit fields: a batch may hold other circuits).
template <class D>
struct LaneMatrices {
  const Chunk<D>& c;
  HWY_INLINE Lanes<D> S(int a, int b) const { return hn::LoadU(c.d, c.S_at(a, b)); }
  HWY_INLINE Lanes<D> bt_coil(int a) const { return hn::LoadU(c.d, c.bt_coil_at(a)); }
  HWY_INLINE Lanes<D> bt_pm(int a) const { return hn::LoadU(c.d, c.bt_pm_at(a)); }
};

template <class D>
HWY_INLINE JaLaneConstants<D> ja_constants(const Chunk<D>& c, int i) {
  return {c.rod(kMsTMag, i), c.rod(kJaA, i),    c.rod(kJaAlpha, i), c.rod(kJaC, i),
          c.rod(kJaK, i),    c.rod(kJaInvA, i), c.rod(kJaInvK, i)};
}

// The law's hooks (one overload per law; the Preisach law's in preisach_lanes-inl.h): the rod's
// constants and state at the step's start, and the commit of a law state the kernel does not
// hold in RodStates (after the step, in the lanes that keep it; the JA law has none).
template <class D>
HWY_INLINE void law_rod(const Chunk<D>& c, const RodStates<D>& s, int i, JaLaneConstants<D>& k,
                        typename JilesAthertonLanes::template Rod<D>& r) {
  k = ja_constants(c, i);
  r = {s.f[kH][i],
       s.f[kMirr][i],
       s.f[kM][i],
       s.f[kAnX][i],
       s.f[kAnL][i],
       s.f[kAnDL][i],
       {{s.f[kJaLangevinY][i], s.f[kJaLangevinE][i]}, {s.f[kJaLagY][i], s.f[kJaLagE][i]}}};
}

// The fields every law's trial has (the Jiles-Atherton law's are all of them): a lane that has
// stopped keeps those of the iterate it stopped at, the others take t's.
template <class M, class T>
HWY_INLINE void keep_common_trial(M done, const T& t, T& tr) {
  tr.M = hn::IfThenElse(done, tr.M, t.M);
  tr.dM_dH = hn::IfThenElse(done, tr.dM_dH, t.dM_dH);
  tr.Mirr = hn::IfThenElse(done, tr.Mirr, t.Mirr);
  tr.inv_mu_r = hn::IfThenElse(done, tr.inv_mu_r, t.inv_mu_r);
  tr.M_next = hn::IfThenElse(done, tr.M_next, t.M_next);
  tr.an_x = hn::IfThenElse(done, tr.an_x, t.an_x);
  tr.an_L = hn::IfThenElse(done, tr.an_L, t.an_L);
  tr.an_dL = hn::IfThenElse(done, tr.an_dL, t.an_dL);
  tr.converged = hn::Or(hn::And(done, tr.converged), hn::AndNot(done, t.converged));
}

// A lane that has stopped keeps the trial of the iterate it stopped at; the others take t
// (and count its full solves of the law in the lanes that are not padding, LaneData::full_solves).
template <class D, class M, class T>
HWY_INLINE void take_trial(D d, M done, M real, const T& t, T& tr, std::size_t& full_solves) {
  if (!hn::AllFalse(d, t.solved))
    full_solves += hn::CountTrue(d, hn::And(real, hn::AndNot(done, t.solved)));
  if (hn::AllFalse(d, done)) {  // no lane has stopped (the first iterates): t as it is
    tr = t;
    return;
  }
  keep_common_trial(done, t, tr);
}

// The JA law's state the step commits beside M and M_irr, into the rods' state (stored with it):
// its anchors as its last evaluation left them (JilesAthertonLaw::commit_trial's
// r.ja_exp = *t.near).
template <class D>
HWY_INLINE void commit_law_state(const typename JilesAthertonLanes::template Start<D>& st,
                                 RodStates<D>& s, int i) {
  s.f[kJaLangevinY][i] = st.near.langevin.y.v;
  s.f[kJaLangevinE][i] = st.near.langevin.e.v;
  s.f[kJaLagY][i] = st.near.lag.y.v;
  s.f[kJaLagE][i] = st.near.lag.e.v;
}
// The law's state kept outside RodStates (the Preisach stacks), after the step, in the lanes
// that keep it: none for the JA law.
template <class D>
HWY_INLINE void law_commit(const Chunk<D>&, const typename JilesAthertonLanes::template Trial<D>*,
                           Mk<D>) {}

// One circuit solve of the vector, and the lanes (not padding) that need it (LaneData's
// lane_solves, vector_solves).
template <class D>
HWY_INLINE void count_solve(const Chunk<D>& c, Mk<D> done) {
  const std::size_t real = c.j < c.L.n ? c.L.n - c.j : 0;
  c.L.lane_solves += hn::CountTrue(c.d, hn::AndNot(done, hn::FirstN(c.d, real)));
  ++c.L.vector_solves;
}

// The lanes' context of the consistent state's solve (gmasim/physics/joint_newton-inl.h, the one
// text the scalar step also runs: laws::joint_newton_start, joint_newton, joint_newton_commit):
// the rods' state in RodStates, the circuit's low-rank solve per lane (laws::rod_solve3: the rods'
// MMF N I + F_pm pm plus their linearised extra), the law's trial kept per lane (take_trial) and
// its state committed (commit_law_state, law_commit), a failure recorded in the lane's record
// (Fails) instead of thrown.
template <class Law, class D>
struct LaneNewton {
  using N = Lanes<D>;
  using M = LaneMask<D>;
  const Chunk<D>& c;
  RodStates<D>& s;
  V<D> I, pm, t1;
  Fails<D>& fails;
  Mk<D> real;  // the lanes that are not padding
  typename Law::template Constants<D> k[kMaxRods];
  typename Law::template Rod<D> rod[kMaxRods];
  typename Law::template Start<D> start[kMaxRods];
  typename Law::template Trial<D> trial[kMaxRods];
  N Rv[kMaxRods], mmf[kMaxRods], ph[kMaxRods];  // the circuit's last solve

  LaneNewton(const Chunk<D>& c_, RodStates<D>& s_, V<D> I_, V<D> pm_, V<D> t1_, Fails<D>& f_)
      : c(c_),
        s(s_),
        I(I_),
        pm(pm_),
        t1(t1_),
        fails(f_),
        real(hn::FirstN(c_.d, c_.j < c_.L.n ? c_.L.n - c_.j : 0)) {}
  HWY_INLINE int rods() const { return c.n; }
  HWY_INLINE laws::RodMagneticT<N> load(int i) const {
    return {s.f[kH][i],     s.f[kHc][i],     s.f[kHprev][i], s.f[kHprev2][i], s.f[kM][i],
            s.f[kMprev][i], s.f[kMprev2][i], s.f[kMuR][i],   s.f[kTau][i],    s.f[kPhi][i]};
  }
  HWY_INLINE void store(int i, const laws::RodMagneticT<N>& r) {
    s.f[kH][i] = r.H.v;
    s.f[kHc][i] = r.Hc.v;
    s.f[kHprev][i] = r.H_prev.v;
    s.f[kHprev2][i] = r.H_prev2.v;
    s.f[kM][i] = r.M.v;
    s.f[kMprev][i] = r.M_prev.v;
    s.f[kMprev2][i] = r.M_prev2.v;
    s.f[kMuR][i] = r.mu_r.v;
    s.f[kTau][i] = r.tau.v;
    s.f[kPhi][i] = r.phi.v;
  }
  HWY_INLINE N kappa(int i) const { return c.rod(kKappa, i); }
  HWY_INLINE N length(int i) const { return c.rod(kLength, i); }
  HWY_INLINE N length_per_area(int i) const { return c.rod(kLengthPerArea, i); }
  HWY_INLINE N series_reluctance(int i) const { return c.rod(kRs, i); }
  HWY_INLINE N area(int i) const { return c.rod(kArea, i); }
  HWY_INLINE N inv_area(int i) const { return c.rod(kInvArea, i); }
  HWY_INLINE void begin(int i) {
    law_rod(c, s, i, k[i], rod[i]);
    start[i] = Law::begin_move(c.d, k[i], rod[i]);
  }
  HWY_INLINE void trial_at(int i, N H, N M_iter, M done) {
    const auto t = Law::joint_trial(c.d, k[i], rod[i], start[i], H.v, M_iter.v, hn::Not(done.m));
    take_trial(c.d, done.m, real, t, trial[i], c.L.full_solves);
  }
  HWY_INLINE N M_of(int i) const { return trial[i].M; }
  HWY_INLINE N dM_dH(int i) const { return trial[i].dM_dH; }
  HWY_INLINE N inv_mu_r(int i) const { return trial[i].inv_mu_r; }
  HWY_INLINE N M_next(int i) const { return trial[i].M_next; }
  HWY_INLINE M converged(int i) const { return {trial[i].converged}; }
  // The branch's reluctance and the rod's MMF in the low-rank system: N I + F_pm pm + extra.
  HWY_INLINE void branch(int i, N R, N extra) {
    Rv[i] = R.v;
    mmf[i] =
        hn::Add(hn::Add(hn::Mul(c.rod(kCoilTurns, i), I), hn::Mul(c.rod(kPmMmf, i), pm)), extra.v);
  }
  // The rods' fluxes (gmasim/physics/rod_circuit-inl.h, the netlist's low-rank solve), where
  // they are still solving; a lane whose solve fails is recorded (kFailCircuit).
  HWY_INLINE M solve(M done) {
    const D d = c.d;
    count_solve(c, done.m);
    const LaneMatrices<D> L{c};
    const M ok = c.n == 3 ? laws::rod_solve3<N>(L, Rv, mmf, N(I), N(pm), ph)
                          : laws::rod_solve_ldlt<0, N>(L, c.n, Rv, mmf, N(I), N(pm), ph);
    fails.mark(d, hn::AndNot(done.m, hn::Not(ok.m)), kFailCircuit, hn::Zero(d), -1, t1,
               hn::Zero(d));
    return {fails.failed};
  }
  HWY_INLINE N flux(int i) const { return ph[i]; }
  // The rod of the largest step names the failure (kFailNewton).
  HWY_INLINE void newton_failed(M bad, N worst, N worst_rod) {
    const D d = c.d;
    for (int i = 0; i < c.n; ++i)
      fails.mark(d, hn::And(bad.m, hn::Eq(worst_rod.v, C(d, static_cast<double>(i)))), kFailNewton,
                 worst.v, i, t1, hn::Zero(d));
  }
  HWY_INLINE M initially_done() const { return {fails.failed}; }
  // M_irr and the law's last evaluation (RodState's an_x, an_L, an_dL) from the kept trial, and
  // its own state (the JA anchors; the Preisach stacks after the step: law_commit).
  HWY_INLINE void commit_law(int i) {
    const auto& tr = trial[i];
    s.f[kMirr][i] = tr.Mirr;
    s.f[kAnX][i] = tr.an_x;
    s.f[kAnL][i] = tr.an_L;
    s.f[kAnDL][i] = tr.an_dL;
    commit_law_state<D>(start[i], s, i);
  }
};

// The consistent magnetic state of one step over the lanes (model/step.cpp's
// consistent_magnetic_update): the one text of joint_newton-inl.h with the lanes' context.
// h is the step (1 at rest: quasi_static, make_state's ramp, no eddy term).
template <class Law, class D>
HWY_INLINE void magnetic_state(LaneNewton<Law, D>& ctx, V<D> h, bool quasi_static) {
  using N = Lanes<D>;
  laws::JointNewtonT<N, kMaxRods> f;
  laws::joint_newton_start(ctx, f, quasi_static, N(hn::Div(C(ctx.c.d, 2.0), h)));
  laws::joint_newton(ctx, f);
  laws::joint_newton_commit(ctx, f, quasi_static);
}

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // GMASIM_LANES_STEP_KERNEL_INL_H_
