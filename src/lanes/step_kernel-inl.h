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
#include "hwy/highway.h"
#include "lanes/ja_lanes-inl.h"
#include "lanes/lane_data.hpp"
#include "lanes/mechanics_lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace gmasim::lanes::HWY_NAMESPACE {

// W lanes of the LaneData from lane j: loads, and the per-lane failure record.
template <class D>
struct Chunk {
  D d;
  LaneData& L;
  std::size_t j;
  int n;  // rods
  V<D> rod(int f, int i) const { return hn::LoadU(d, L.rod(f, i) + j); }
  V<D> glob(int f) const { return hn::LoadU(d, L.glob(f) + j); }
};

// The first failure of each lane in this step: code, value, rod and time (kFail...).
template <class D>
struct Fails {
  Mk<D> failed;
  V<D> code, value, rod, t, bound;
  void mark(D d, Mk<D> m, FailCode c, V<D> val, int rod_index, V<D> time, V<D> limit) {
    const Mk<D> nw = hn::AndNot(failed, m);
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

// The low-rank circuit solve (circuit/netlist.cpp, rod_solve) per lane: with D = diag(1/R),
// F the rods' MMFs and u = I psi_coil + pm psi_pm:  (D^-1 + S) z' = B^T u - S D F,
// z = z' + D F, phi_r = (B^T u - S z)_r + F_r) / R_r. Cholesky in place; ok is false where
// the matrix is not positive definite or z is not finite.
template <class D>
HWY_INLINE Mk<D> circuit_solve(const Chunk<D>& c, const V<D>* R, const V<D>* mmf, V<D> I, V<D> pm,
                               V<D>* phi) {
  const D d = c.d;
  const int n = c.n;
  V<D> A[kMaxRods][kMaxRods], DF[kMaxRods], Btu[kMaxRods], y[kMaxRods];
  for (int a = 0; a < n; ++a) {
    DF[a] = hn::Div(mmf[a], R[a]);
    Btu[a] = hn::Add(hn::Mul(I, hn::LoadU(d, c.L.bt_coil(a) + c.j)),
                     hn::Mul(pm, hn::LoadU(d, c.L.bt_pm(a) + c.j)));
    for (int b = 0; b < n; ++b) A[a][b] = hn::LoadU(d, c.L.S(a, b) + c.j);
  }
  for (int a = 0; a < n; ++a) {
    V<D> s = hn::Zero(d);
    for (int b = 0; b < n; ++b) s = hn::Add(s, hn::Mul(A[a][b], DF[b]));
    y[a] = hn::Sub(Btu[a], s);
  }
  for (int a = 0; a < n; ++a) A[a][a] = hn::Add(A[a][a], R[a]);
  Mk<D> ok = hn::FirstN(d, hn::Lanes(d));
  for (int a = 0; a < n; ++a) {  // A = L L^T, L in the lower triangle
    V<D> dd = A[a][a];
    for (int k = 0; k < a; ++k) dd = hn::Sub(dd, hn::Mul(A[a][k], A[a][k]));
    ok = hn::And(ok, hn::Gt(dd, hn::Zero(d)));
    A[a][a] = hn::Sqrt(dd);
    for (int b = a + 1; b < n; ++b) {
      V<D> s = A[b][a];
      for (int k = 0; k < a; ++k) s = hn::Sub(s, hn::Mul(A[b][k], A[a][k]));
      A[b][a] = hn::Div(s, A[a][a]);
    }
  }
  for (int a = 0; a < n; ++a) {  // L w = y
    for (int k = 0; k < a; ++k) y[a] = hn::Sub(y[a], hn::Mul(A[a][k], y[k]));
    y[a] = hn::Div(y[a], A[a][a]);
  }
  for (int a = n - 1; a >= 0; --a) {  // L^T z' = w, then z = z' + D F
    for (int k = a + 1; k < n; ++k) y[a] = hn::Sub(y[a], hn::Mul(A[k][a], y[k]));
    y[a] = hn::Div(y[a], A[a][a]);
  }
  for (int a = 0; a < n; ++a) {
    y[a] = hn::Add(y[a], DF[a]);
    ok = hn::And(ok, hn::IsFinite(y[a]));
  }
  for (int a = 0; a < n; ++a) {
    V<D> v = Btu[a];
    for (int b = 0; b < n; ++b) v = hn::Sub(v, hn::Mul(hn::LoadU(d, c.L.S(a, b) + c.j), y[b]));
    phi[a] = hn::Div(hn::Add(v, mmf[a]), R[a]);
  }
  return ok;
}

template <class D>
HWY_INLINE JaLaneConstants<D> ja_constants(const Chunk<D>& c, int i) {
  return {c.rod(kMsTMag, i), c.rod(kJaA, i), c.rod(kJaAlpha, i), c.rod(kJaC, i), c.rod(kJaK, i)};
}

// Newton's method on the rods' fields (model/step.cpp, consistent_magnetic_update): each rod
// linearised at its iterate into a branch U = R_eff phi + U_off, the circuit solved, the
// field moved to the one its flux implies. Per lane: a converged lane stops moving; the loop
// ends when every lane has converged or failed, or at the cap (60), where a lane within
// 1 mA/m is accepted and the others fail (kFailNewton, the rod of the largest step).
template <class Law, class D>
HWY_INLINE void newton_fields(const Chunk<D>& c, RodStates<D>& s, V<D> I, V<D> pm, V<D> h, V<D> t1,
                              V<D>* H, V<D>* M, V<D>* B0, Fails<D>& fails) {
  const D d = c.d;
  const int n = c.n;
  constexpr double kMu0 = physics::kMu0;
  V<D> g[kMaxRods], e0[kMaxRods], Bs[kMaxRods], mud[kMaxRods];
  for (int i = 0; i < n; ++i) {
    B0[i] = hn::Mul(C(d, kMu0), hn::Add(s.f[kH][i], s.f[kM][i]));
    e0[i] = hn::Sub(s.f[kHc][i], s.f[kH][i]);
    g[i] = hn::Div(hn::Mul(C(d, 2.0), c.rod(kKappa, i)), h);
    H[i] = hn::Sub(hn::Mul(C(d, 2.0), s.f[kH][i]), s.f[kHprev][i]);
    M[i] =
        hn::Add(s.f[kM][i], hn::Mul(hn::Sub(s.f[kMuR][i], C(d, 1.0)), hn::Sub(H[i], s.f[kH][i])));
  }
  Mk<D> done = fails.failed;
  for (int it = 0; !hn::AllTrue(d, done); ++it) {
    V<D> R[kMaxRods], mmf[kMaxRods], phi[kMaxRods];
    for (int i = 0; i < n; ++i) {
      V<D> chi;
      // a lane that has converged keeps the iterate it converged at
      M[i] = hn::IfThenElse(done, M[i],
                            Law::trial(d, ja_constants(c, i), s.f[kH][i], s.f[kMirr][i], s.f[kM][i],
                                       H[i], M[i], chi));
      Bs[i] = hn::Mul(C(d, kMu0), hn::Add(H[i], M[i]));
      mud[i] = hn::Mul(C(d, kMu0), hn::Add(C(d, 1.0), chi));
      const V<D> l = c.rod(kLength, i);
      R[i] =
          hn::Add(hn::Mul(hn::Div(l, c.rod(kArea, i)), hn::Add(hn::Div(C(d, 1.0), mud[i]), g[i])),
                  c.rod(kRs, i));
      const V<D> extra = hn::Mul(
          hn::Neg(l),
          hn::Sub(hn::Sub(hn::Sub(H[i], hn::Div(Bs[i], mud[i])), hn::Mul(g[i], B0[i])), e0[i]));
      mmf[i] =
          hn::Add(hn::Add(hn::Mul(c.rod(kCoilTurns, i), I), hn::Mul(c.rod(kPmMmf, i), pm)), extra);
    }
    const Mk<D> ok = circuit_solve(c, R, mmf, I, pm, phi);
    fails.mark(d, hn::AndNot(done, hn::Not(ok)), kFailCircuit, hn::Zero(d), -1, t1, hn::Zero(d));
    done = hn::Or(done, fails.failed);
    V<D> worst = hn::Zero(d), worst_rod = hn::Zero(d);
    Mk<D> converged = hn::FirstN(d, hn::Lanes(d));
    const V<D> damping = C(d, it < 8 ? 1.0 : 0.5);
    for (int i = 0; i < n; ++i) {
      const V<D> dH = hn::Div(hn::Sub(hn::Div(phi[i], c.rod(kArea, i)), Bs[i]), mud[i]);
      const V<D> adH = hn::Abs(dH);
      const Mk<D> larger = hn::Gt(adH, worst);
      worst = hn::IfThenElse(larger, adH, worst);
      worst_rod = hn::IfThenElse(larger, C(d, static_cast<double>(i)), worst_rod);
      converged =
          hn::And(converged, hn::Le(adH, hn::Add(C(d, 1e-7), hn::Mul(C(d, 1e-11), hn::Abs(H[i])))));
      H[i] = hn::IfThenElse(done, H[i], hn::Add(H[i], hn::Mul(damping, dH)));
    }
    done = hn::Or(done, converged);
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
    done = hn::Or(done, stop);
  }
}

// Commit of the end-of-step magnetic state (model/step.cpp, consistent_magnetic_update's
// last loop): the law's move to H1, the eddy field (eq. 7, trapezoidal), the rod's flux.
template <class Law, class D>
HWY_INLINE void commit_fields(const Chunk<D>& c, RodStates<D>& s, V<D> h, const V<D>* H,
                              const V<D>* M, const V<D>* B0) {
  const D d = c.d;
  constexpr double kMu0 = physics::kMu0;
  for (int i = 0; i < c.n; ++i) {
    V<D> chi;
    V<D> Mirr = s.f[kMirr][i], Mr = s.f[kM][i];
    Law::commit(d, ja_constants(c, i), s.f[kH][i], Mirr, Mr, H[i], M[i], chi);
    const V<D> B1 = hn::Mul(C(d, kMu0), hn::Add(H[i], Mr));
    const V<D> kappa = c.rod(kKappa, i);
    // eddy_static_field_trapezoid: H1 + 2 kappa (B1 - B0)/h - (Hc0 - H0)
    s.f[kHc][i] =
        hn::Sub(hn::Add(H[i], hn::Div(hn::Mul(hn::Mul(C(d, 2.0), kappa), hn::Sub(B1, B0[i])), h)),
                hn::Sub(s.f[kHc][i], s.f[kH][i]));
    s.f[kHprev][i] = s.f[kH][i];
    s.f[kH][i] = H[i];
    s.f[kMirr][i] = Mirr;
    s.f[kM][i] = Mr;
    s.f[kMprev][i] = Mr;
    s.f[kMuR][i] = hn::Add(C(d, 1.0), chi);
    s.f[kTau][i] = hn::Mul(hn::Mul(C(d, kMu0), s.f[kMuR][i]), kappa);
    s.f[kPhi][i] = hn::Mul(B1, c.rod(kArea, i));
  }
}

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // GMASIM_LANES_STEP_KERNEL_INL_H_
