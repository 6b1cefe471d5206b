// The consistent step over SIMD lanes (docs/lanes.md): model/step.cpp's step_law for W
// simulations at once, in the same stages -- the consistent magnetic state by Newton's method
// (per lane, masked), the mechanics (eq. 11-18), the sensor mount, the outputs -- and with the
// same checks (step() and run_loop()), recorded per lane instead of thrown. Included once per
// target by src/lanes/step_lanes.cpp (hwy/foreach_target.h).
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

// Rod a's right-hand side of the k x k system, (B^T u + F)_a = I (B^T psi_coil)_a + pm
// (B^T psi_pm)_a + F_a (rod_solve's x, in its order of operations).
template <class D>
HWY_INLINE V<D> rod_rhs(const Chunk<D>& c, int a, V<D> I, V<D> pm, V<D> F) {
  const D d = c.d;
  return hn::Add(
      hn::Add(hn::Mul(I, hn::LoadU(d, c.bt_coil_at(a))), hn::Mul(pm, hn::LoadU(d, c.bt_pm_at(a)))),
      F);
}

// The low-rank circuit solve (circuit/netlist.cpp, rod_solve and solve_circuit) per lane: with
// F the rods' MMFs and u = I psi_coil + pm psi_pm, the rod fluxes themselves solve
//   (diag(R) + S) phi = B^T u + F
// (L D L^T, no square roots; no reciprocal of R). ok is false where a pivot is not positive or
// phi is not finite. One division per pivot, as rod_solve.
// Three rods (the built-in actuator): netlist.cpp's rod_solve3, A = S + diag(R) solved by its
// adjugate with one division, Sylvester's criterion for the pivots.
template <class D>
HWY_INLINE Mk<D> circuit_solve3(const Chunk<D>& c, const V<D>* R, const V<D>* mmf, V<D> I, V<D> pm,
                                V<D>* phi) {
  const D d = c.d;
  auto S = [&](int a, int b) { return hn::LoadU(d, c.S_at(a, b)); };
  V<D> x[3];
  for (int a = 0; a < 3; ++a) x[a] = rod_rhs(c, a, I, pm, mmf[a]);
  const V<D> a00 = hn::Add(S(0, 0), R[0]), a10 = S(1, 0), a11 = hn::Add(S(1, 1), R[1]);
  const V<D> a20 = S(2, 0), a21 = S(2, 1), a22 = hn::Add(S(2, 2), R[2]);
  auto minor = [&](V<D> p, V<D> q, V<D> r, V<D> s) {
    return hn::Sub(hn::Mul(p, q), hn::Mul(r, s));
  };
  const V<D> c00 = minor(a11, a22, a21, a21), c01 = minor(a20, a21, a10, a22);
  const V<D> c02 = minor(a10, a21, a20, a11), c11 = minor(a00, a22, a20, a20);
  const V<D> c12 = minor(a10, a20, a00, a21), m2 = minor(a00, a11, a10, a10);
  const V<D> det = hn::Add(hn::Add(hn::Mul(a00, c00), hn::Mul(a10, c01)), hn::Mul(a20, c02));
  const V<D> zero = hn::Zero(d);
  Mk<D> ok = hn::And(hn::And(hn::Gt(a00, zero), hn::Gt(m2, zero)), hn::Gt(det, zero));
  const V<D> inv_det = hn::Div(C(d, 1.0), det);
  auto row = [&](V<D> p, V<D> q, V<D> r) {
    return hn::Add(hn::Add(hn::Mul(p, x[0]), hn::Mul(q, x[1])), hn::Mul(r, x[2]));
  };
  phi[0] = hn::Mul(row(c00, c01, c02), inv_det);
  phi[1] = hn::Mul(row(c01, c11, c12), inv_det);
  phi[2] = hn::Mul(row(c02, c12, m2), inv_det);
  for (int a = 0; a < 3; ++a) ok = hn::And(ok, hn::IsFinite(phi[a]));
  return ok;
}

template <class D>
HWY_INLINE Mk<D> circuit_solve(const Chunk<D>& c, const V<D>* R, const V<D>* mmf, V<D> I, V<D> pm,
                               V<D>* phi) {
  const D d = c.d;
  const int n = c.n;
  if (n == 3) return circuit_solve3(c, R, mmf, I, pm, phi);
  V<D> S[kMaxRods][kMaxRods], A[kMaxRods][kMaxRods], x[kMaxRods], piv[kMaxRods], inv_piv[kMaxRods];
  for (int a = 0; a < n; ++a) {
    x[a] = rod_rhs(c, a, I, pm, mmf[a]);
    for (int b = 0; b < n; ++b) S[a][b] = hn::LoadU(d, c.S_at(a, b));
  }
  Mk<D> ok = hn::FirstN(d, hn::Lanes(d));
  for (int j = 0; j < n; ++j) {  // L D L^T of S + diag(R), unit L below the diagonal of A
    V<D> dd = hn::Add(S[j][j], R[j]);
    for (int p = 0; p < j; ++p) dd = hn::Sub(dd, hn::Mul(hn::Mul(A[j][p], A[j][p]), piv[p]));
    ok = hn::And(ok, hn::Gt(dd, hn::Zero(d)));
    piv[j] = dd;
    inv_piv[j] = hn::Div(C(d, 1.0), dd);  // one division per pivot
    for (int i = j + 1; i < n; ++i) {
      V<D> a = S[i][j];
      for (int p = 0; p < j; ++p) a = hn::Sub(a, hn::Mul(hn::Mul(A[i][p], A[j][p]), piv[p]));
      A[i][j] = hn::Mul(a, inv_piv[j]);
    }
  }
  for (int i = 0; i < n; ++i)
    for (int p = 0; p < i; ++p) x[i] = hn::Sub(x[i], hn::Mul(A[i][p], x[p]));
  for (int i = n - 1; i >= 0; --i) {
    x[i] = hn::Mul(x[i], inv_piv[i]);
    for (int p = i + 1; p < n; ++p) x[i] = hn::Sub(x[i], hn::Mul(A[p][i], x[p]));
  }
  for (int a = 0; a < n; ++a) {
    phi[a] = x[a];
    ok = hn::And(ok, hn::IsFinite(x[a]));
  }
  return ok;
}

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

// Per rod, what the Newton solve fixes at the step's start and what it ends with.
// g = 2 kappa / h (eddy_static_field_trapezoid; 0 at rest).
template <class Law, class D>
struct Magnetic {
  V<D> H[kMaxRods], Mg[kMaxRods], B0[kMaxRods], Bs[kMaxRods], g[kMaxRods];
  typename Law::template Start<D> start[kMaxRods];  // each rod's move (its anchors, JA)
  typename Law::template Trial<D> trial[kMaxRods];
};
template <class D>
HWY_INLINE void law_commit(const Chunk<D>&, const Magnetic<JilesAthertonLanes, D>&, Mk<D>) {}
// The law's state the step commits beside M and M_irr, into the rods' state (stored with it):
// the JA law's anchors as its last evaluation left them (JilesAthertonLaw::commit_trial's
// r.ja_exp = *t.near).
template <class D>
HWY_INLINE void commit_law_state(const Magnetic<JilesAthertonLanes, D>& mg, RodStates<D>& s,
                                 int i) {
  const auto& near = mg.start[i].near;
  s.f[kJaLangevinY][i] = near.langevin.y.v;
  s.f[kJaLangevinE][i] = near.langevin.e.v;
  s.f[kJaLagY][i] = near.lag.y.v;
  s.f[kJaLagE][i] = near.lag.e.v;
}

// model/step.cpp's next_correction_within_tolerance per lane: after an undamped correction the
// next one is bounded by 2 law_steps (the sum of the laws' own steps |M_next - M*|); true where
// that bound is within a quarter of every rod's field tolerance, 1e-7 A/m + 1e-11 |H|.
template <class D>
HWY_INLINE Mk<D> next_correction_within_tolerance(D d, int n, V<D> law_steps, const V<D>* H) {
  const V<D> bound = hn::Mul(C(d, 2.0), law_steps);
  Mk<D> within = hn::FirstN(d, hn::Lanes(d));
  for (int i = 0; i < n; ++i)
    within = hn::And(
        within, hn::Le(bound, hn::Mul(C(d, 0.25),
                                      hn::Add(C(d, 1e-7), hn::Mul(C(d, 1e-11), hn::Abs(H[i]))))));
  return within;
}

// One circuit solve of the vector, and the lanes (not padding) that need it (LaneData's
// lane_solves, vector_solves).
template <class D>
HWY_INLINE void count_solve(const Chunk<D>& c, Mk<D> done) {
  const std::size_t real = c.j < c.L.n ? c.L.n - c.j : 0;
  c.L.lane_solves += hn::CountTrue(c.d, hn::AndNot(done, hn::FirstN(c.d, real)));
  ++c.L.vector_solves;
}

// The lanes of an iterate that neither converged nor are done, where their largest step is not
// finite or at the cap (60): accepted where it is within 1 mA/m, failed otherwise (kFailNewton,
// named by the rod of that step). Returns the lanes that stop.
template <class D>
HWY_INLINE Mk<D> stopped(D d, int n, Mk<D> done, V<D> worst, V<D> worst_rod, int it, V<D> t1,
                         Fails<D>& fails) {
  const Mk<D> stop =
      hn::AndNot(done, hn::Or(hn::Not(hn::IsFinite(worst)),
                              it == 60 ? hn::FirstN(d, hn::Lanes(d)) : hn::FirstN(d, 0)));
  const Mk<D> accept = hn::And(stop, hn::Le(worst, C(d, 1e-3)));  // 1 mA/m
  const Mk<D> bad = hn::AndNot(accept, stop);
  if (!hn::AllFalse(d, bad)) {
    for (int i = 0; i < n; ++i)  // the rod of the largest step names the failure
      fails.mark(d, hn::And(bad, hn::Eq(worst_rod, C(d, static_cast<double>(i)))), kFailNewton,
                 worst, i, t1, hn::Zero(d));
  }
  return stop;
}

// Rod i's flux density B0 at the step's start, its eddy terms e0 = H_c - H and g = 2 kappa / h
// and the first guess (H, M) of newton_fields; quasi_static: no eddy term, the guess (H_n, M_n).
template <class Law, class D>
HWY_INLINE void first_guess(const Chunk<D>& c, const RodStates<D>& s, int i, V<D> two_over_h,
                            bool quasi_static, Magnetic<Law, D>& mg, V<D>& e0) {
  const D d = c.d;
  mg.B0[i] = hn::Mul(C(d, physics::kMu0), hn::Add(s.f[kH][i], s.f[kM][i]));
  if (quasi_static) {
    e0 = mg.g[i] = hn::Zero(d);
    mg.H[i] = s.f[kH][i];
    mg.Mg[i] = s.f[kM][i];
    return;
  }
  e0 = hn::Sub(s.f[kHc][i], s.f[kH][i]);
  mg.g[i] = hn::Mul(c.rod(kKappa, i), two_over_h);
  mg.H[i] = hn::Add(hn::Mul(C(d, 3.0), hn::Sub(s.f[kH][i], s.f[kHprev][i])), s.f[kHprev2][i]);
  mg.Mg[i] = hn::Add(hn::Mul(C(d, 3.0), hn::Sub(s.f[kM][i], s.f[kMprev][i])), s.f[kMprev2][i]);
}

// Newton's method on the rods' fields and magnetisations jointly (model/step.cpp,
// consistent_magnetic_update): the first guess extrapolated quadratically from the last three
// steps (H = 3 (H_n - H_n-1) + H_n-2, M likewise); at each iterate (H*, M*) each rod's law
// evaluated once (joint_trial: no inner solve), its magnetisation corrected by the law's Newton
// step to M_next and linearised into a branch U = R_eff phi + U_off, the circuit solved, H* moved
// to the field its flux implies and M* to M_next + dM/dH dH. Per lane: a lane whose field
// corrections are all below 1e-7 A/m + 1e-11 |H| and whose laws all hold (|g| <= 1e-12 M_s^T)
// keeps that iterate and its trial (the last evaluation is committed); so does a lane, after an
// undamped correction (iterates 1-8), whose laws all hold and whose next correction is bounded
// within a quarter of every rod's field tolerance (next_correction_within_tolerance) -- without
// the confirming solve, which runs only while some lane of the vector still needs it. The loop
// ends when every lane has converged or failed, or at the cap (60), where a lane whose largest
// step (field or law) is within 1 mA/m is accepted and the others fail (kFailNewton, the rod of
// that step). quasi_static (make_state's ramp, consistent_magnetic_update's quasi_static): no
// eddy term, the first guess at H_n and M_n.
template <class Law, class D>
HWY_INLINE void newton_fields(const Chunk<D>& c, const RodStates<D>& s, V<D> I, V<D> pm, V<D> h,
                              V<D> t1, bool quasi_static, Magnetic<Law, D>& mg, Fails<D>& fails) {
  const D d = c.d;
  const int n = c.n;
  constexpr double kMu0 = physics::kMu0;
  V<D> e0[kMaxRods], inv_mud[kMaxRods];
  const V<D>* g = mg.g;
  const V<D> two_over_h = hn::Div(C(d, 2.0), h);
  auto& start = mg.start;
  typename Law::template Rod<D> rod[kMaxRods];
  typename Law::template Constants<D> k[kMaxRods];
  for (int i = 0; i < n; ++i) {
    law_rod(c, s, i, k[i], rod[i]);
    start[i] = Law::begin_move(d, k[i], rod[i]);
    first_guess(c, s, i, two_over_h, quasi_static, mg, e0[i]);
  }
  Mk<D> done = fails.failed;
  const Mk<D> real = hn::FirstN(d, c.j < c.L.n ? c.L.n - c.j : 0);
  for (int it = 0; !hn::AllTrue(d, done); ++it) {
    V<D> R[kMaxRods], mmf[kMaxRods], phi[kMaxRods];
    V<D> law_steps = hn::Zero(d);  // sum over the rods of |M_next - M*|
    Mk<D> laws_hold = hn::FirstN(d, hn::Lanes(d));
    for (int i = 0; i < n; ++i) {
      const auto t = Law::joint_trial(d, k[i], rod[i], start[i], mg.H[i], mg.Mg[i], hn::Not(done));
      auto& tr = mg.trial[i];
      take_trial(d, done, real, t, tr, c.L.full_solves);
      laws_hold = hn::And(laws_hold, tr.converged);
      law_steps = hn::Add(law_steps, hn::Abs(hn::Sub(tr.M_next, mg.Mg[i])));
      mg.Bs[i] = hn::Mul(C(d, kMu0), hn::Add(mg.H[i], tr.M_next));
      inv_mud[i] = hn::Mul(tr.inv_mu_r, C(d, 1.0 / kMu0));
      R[i] = hn::Add(hn::Mul(c.rod(kLengthPerArea, i), hn::Add(inv_mud[i], g[i])), c.rod(kRs, i));
      const V<D> extra = hn::Mul(
          hn::Neg(c.rod(kLength, i)),
          hn::Sub(hn::Sub(hn::Sub(mg.H[i], hn::Mul(mg.Bs[i], inv_mud[i])), hn::Mul(g[i], mg.B0[i])),
                  e0[i]));
      mmf[i] =
          hn::Add(hn::Add(hn::Mul(c.rod(kCoilTurns, i), I), hn::Mul(c.rod(kPmMmf, i), pm)), extra);
    }
    if (it >= 1 && it <= 8) {  // the iterate has converged without the confirming solve
      done =
          hn::Or(done, hn::And(laws_hold, next_correction_within_tolerance(d, n, law_steps, mg.H)));
      if (hn::AllTrue(d, done)) break;
    }
    count_solve(c, done);
    const Mk<D> ok = circuit_solve(c, R, mmf, I, pm, phi);
    fails.mark(d, hn::AndNot(done, hn::Not(ok)), kFailCircuit, hn::Zero(d), -1, t1, hn::Zero(d));
    done = hn::Or(done, fails.failed);
    V<D> worst = hn::Zero(d), worst_rod = hn::Zero(d), dH[kMaxRods];
    Mk<D> converged = hn::FirstN(d, hn::Lanes(d));
    for (int i = 0; i < n; ++i) {
      dH[i] = hn::Mul(hn::Sub(hn::Mul(phi[i], c.rod(kInvArea, i)), mg.Bs[i]), inv_mud[i]);
      const V<D> adH = hn::Abs(dH[i]);
      // the rod's Newton step: its field's and its law's; NaN propagates
      const V<D> dM = hn::Abs(hn::Sub(mg.trial[i].M_next, mg.Mg[i]));
      const V<D> step = hn::IfThenElse(hn::Le(dM, adH), adH, dM);
      const Mk<D> larger = hn::Not(hn::Le(step, worst));
      worst = hn::IfThenElse(larger, step, worst);
      worst_rod = hn::IfThenElse(larger, C(d, static_cast<double>(i)), worst_rod);
      converged = hn::And(hn::And(converged, mg.trial[i].converged),
                          hn::Le(adH, hn::Add(C(d, 1e-7), hn::Mul(C(d, 1e-11), hn::Abs(mg.H[i])))));
    }
    done = hn::Or(done, converged);
    done = hn::Or(done, stopped(d, n, done, worst, worst_rod, it, t1, fails));
    const V<D> damping = C(d, it < 8 ? 1.0 : 0.5);
    for (int i = 0; i < n; ++i) {  // the lanes still iterating: the next iterate
      const V<D> step = hn::Mul(damping, dH[i]);
      mg.H[i] = hn::IfThenElse(done, mg.H[i], hn::Add(mg.H[i], step));
      const auto& tr = mg.trial[i];
      mg.Mg[i] = hn::IfThenElse(done, mg.Mg[i], hn::Add(tr.M_next, hn::Mul(tr.dM_dH, step)));
    }
  }
}

// Commit of the end-of-step magnetic state (model/step.cpp, commit_rod): the last Newton
// trial at H1 as it is (its M, M_irr and flux density B1), the eddy field (eq. 7,
// trapezoidal), the first guess's histories, mu_r = 1 + dM/dH and the rod's flux.
template <class Law, class D>
HWY_INLINE void commit_fields(const Chunk<D>& c, RodStates<D>& s, bool quasi_static,
                              const Magnetic<Law, D>& mg) {
  const D d = c.d;
  constexpr double kMu0 = physics::kMu0;
  for (int i = 0; i < c.n; ++i) {
    const auto& tr = mg.trial[i];
    const V<D> H1 = mg.H[i], B1 = hn::Mul(C(d, kMu0), hn::Add(H1, tr.M)), kappa = c.rod(kKappa, i);
    s.f[kMprev2][i] = s.f[kMprev][i];
    s.f[kMprev][i] = s.f[kM][i];
    s.f[kMirr][i] = tr.Mirr;
    s.f[kM][i] = tr.M;
    // eddy_static_field_trapezoid: H1 + g (B1 - B0) - (Hc0 - H0); at rest H_c = H1
    s.f[kHc][i] = quasi_static ? H1
                               : hn::Sub(hn::Add(H1, hn::Mul(mg.g[i], hn::Sub(B1, mg.B0[i]))),
                                         hn::Sub(s.f[kHc][i], s.f[kH][i]));
    s.f[kHprev2][i] = s.f[kHprev][i];
    s.f[kHprev][i] = s.f[kH][i];
    s.f[kH][i] = H1;
    s.f[kMuR][i] = hn::Add(C(d, 1.0), tr.dM_dH);
    s.f[kTau][i] = hn::Mul(hn::Mul(C(d, kMu0), s.f[kMuR][i]), kappa);
    s.f[kPhi][i] = hn::Mul(B1, c.rod(kArea, i));
    commit_law_state(mg, s, i);
    s.f[kAnX][i] = tr.an_x;
    s.f[kAnL][i] = tr.an_L;
    s.f[kAnDL][i] = tr.an_dL;
  }
}

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // GMASIM_LANES_STEP_KERNEL_INL_H_
