// The batched step's stages after the magnetic state, its chunk loop and its run-time
// dispatch (docs/lanes.md). Compiled once per SIMD target by hwy/foreach_target.h; the CPU's
// best target is chosen at run time (HWY_DYNAMIC_DISPATCH). Built with -ffp-contract=off
// (CMakeLists.txt): each lane equals the width-1 instance bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "lanes/step_lanes.cpp"
#include <type_traits>

#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
#include "lanes/number_lanes-inl.h"
#include "lanes/preisach_lanes-inl.h"
#include "lanes/step_kernel-inl.h"

HWY_BEFORE_NAMESPACE();
namespace gmasim::lanes::HWY_NAMESPACE {

// Stage 3 (model/step.cpp, stage_strain and stage_mechanics): each rod's Delta-E modulus,
// strain, force and stiffness (eq. 11-14, 17: laws::rod_mechanics), its load stiffness
// (eq. 18: chain_stiffness) and its oscillator over the step (eq. 15-16, stiffness at mid-step:
// mid_step_stiffness, oscillator_step); then the sensor mount's probe (base_excited_step). The
// laws are gmasim/physics's own, instantiated over the lanes' number type (Lanes<D>).
template <class D>
HWY_INLINE void mechanics(const Chunk<D>& c, RodStates<D>& s, V<D> h, V<D> t1, Fails<D>& fails) {
  using N = Lanes<D>;
  const D d = c.d;
  const int n = c.n;
  const Structure& st = c.L.st;
  N F0[kMaxRods], K0[kMaxRods], compliance[kMaxRods];
  const N lambda_s = c.glob(kLambdaS);
  for (int i = 0; i < n; ++i) {
    F0[i] = s.f[kF][i];
    K0[i] = N(s.f[kKRod][i]) + N(s.f[kKLoad][i]);
    const laws::DeltaETermsT<N> dE{c.rod(kInvEs, i), c.rod(kRot, i), c.rod(kCoupling, i),
                                   c.rod(kMu0Ms2, i), c.rod(kSdE, i)};
    laws::ExpPointT<N> prestress{s.f[kPrestressY][i], s.f[kPrestressE][i]};
    const laws::RodMechanicsT<N> k = laws::rod_mechanics<N>(
        s.f[kM][i], c.rod(kInvMsTE, i), dE, c.rod(kInvMsStrain, i), lambda_s, c.rod(kSigmaP, i),
        c.rod(kFourSpOverLs, i), c.rod(kArea, i), c.rod(kAreaOverLength, i),
        c.rod(kLengthPerArea, i), c.rod(kJointCompl, i), prestress);
    s.f[kPrestressY][i] = prestress.y.v;
    s.f[kPrestressE][i] = prestress.e.v;
    s.f[kE][i] = k.E_Pa.v;
    s.f[kLambda][i] = k.lambda.v;
    s.f[kF][i] = k.F_N.v;
    s.f[kKRod][i] = k.k_rod_N_per_m.v;
    compliance[i] = k.compliance_m_per_N;
  }
  for (int i = 0; i < n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    const N k_load = laws::chain_stiffness<N>(c.rod(kFixedCompl, i), compliance, st.chain[u].data(),
                                              st.chain_count[u]);
    s.f[kKLoad][i] = k_load.v;
    const N K = laws::mid_step_stiffness<N>(K0[i], s.f[kKRod][i], k_load);
    s.f[kKOsc][i] = K.v;
    N x = s.f[kX][i], v = s.f[kV][i];
    laws::ExpPointT<N> decay{s.f[kOscDecayY][i], s.f[kOscDecayE][i]};
    laws::oscillator_step<N>(c.rod(kMassOsc, i), c.rod(kInvMassOsc, i), c.rod(kDampOsc, i), K,
                             F0[i], s.f[kF][i], h, x, v, decay);
    s.f[kX][i] = x.v;
    s.f[kV][i] = v.v;
    s.f[kOscDecayY][i] = decay.y.v;
    s.f[kOscDecayE][i] = decay.e.v;
    fails.check(d, s.f[kX][i], C(d, 1.0), kFailX, i, t1);
  }
}

// The probe on its bracket (model/step.cpp, advance_sensor_mount) and the outputs
// (finish_outputs): y = sum x (eq. 20) + the probe's deflection (+ x_T), B of the coil.
template <class D>
HWY_INLINE void mount_and_outputs(const Chunk<D>& c, RodStates<D>& s, V<D>* g, V<D> h, V<D> t1,
                                  Fails<D>& fails) {
  using N = Lanes<D>;
  const D d = c.d;
  const Structure& st = c.L.st;
  V<D> y = hn::Zero(d);  // eq. (20): y_stack = sum x
  for (int i = 0; i < c.n; ++i) y = hn::Add(y, s.f[kX][i]);
  g[kYStack] = y;
  if (st.mount) {
    // the bracket's base (model/step.cpp, mount_base_m): the recoil p / M or the output y_stack
    V<D> q1 = y;
    if (!st.mount_on_output) {
      V<D> p = hn::Zero(d);
      for (int i = 0; i < c.n; ++i) p = hn::Add(p, hn::Mul(c.rod(kMomMass, i), s.f[kX][i]));
      q1 = hn::Div(p, c.glob(kActMass));
    }
    N z = g[kZ], zv = g[kZv];
    laws::ExpPointT<N> decay{g[kMountDecayY], g[kMountDecayE]};
    laws::base_excited_step<N>(c.glob(kMountMass), c.glob(kMountInvMass), c.glob(kMountC),
                               c.glob(kMountK), g[kQ], q1, h, z, zv, decay);
    g[kZ] = z.v;
    g[kZv] = zv.v;
    g[kMountDecayY] = decay.y.v;
    g[kMountDecayE] = decay.e.v;
    g[kQ] = q1;
    fails.check(d, g[kZ], C(d, 1.0), kFailZ, -1, t1);
  }
  if (st.mount) y = st.mount_on_output ? g[kZ] : hn::Add(y, hn::Sub(g[kZ], g[kQ]));
  if (st.xT_in_output) y = hn::Add(y, c.glob(kXT));
  g[kY] = y;
  V<D> phi = hn::Zero(d);
  for (int k = 0; k < st.sensor_count; ++k)
    phi = hn::Add(phi, s.f[kPhi][st.sensor_rods[static_cast<std::size_t>(k)]]);
  g[kBSensor] = hn::Div(phi, c.glob(kSensorArea));
  for (int i = 0; i < c.n; ++i) s.f[kB][i] = hn::Mul(s.f[kPhi][i], c.rod(kInvArea, i));
}

// run_loop's checks after the step (gmasim/run_loop.hpp, advance): y and B finite, every
// rod's strain, displacement and flux density possible (check_physical_validity).
template <class D>
HWY_INLINE void run_loop_checks(const Chunk<D>& c, const RodStates<D>& s, const V<D>* g, V<D> t,
                                Fails<D>& fails) {
  const D d = c.d;
  const V<D> zero = hn::Zero(d);
  fails.mark(d, hn::Not(hn::IsFinite(g[kY])), kFailY, g[kY], -1, t, zero);
  fails.mark(d, hn::Not(hn::IsFinite(g[kBSensor])), kFailBSensor, g[kBSensor], -1, t, zero);
  for (int i = 0; i < c.n; ++i) {
    const V<D> strain_bound = c.rod(kStrainBound, i), length = c.rod(kLength, i);
    fails.mark(d, hn::Not(hn::Le(hn::Abs(s.f[kLambda][i]), strain_bound)), kFailStrain,
               s.f[kLambda][i], i, t, strain_bound);
    fails.mark(d, hn::Not(hn::Lt(hn::Abs(s.f[kX][i]), length)), kFailDisplacement, s.f[kX][i], i, t,
               length);
    const V<D> bound =
        hn::Mul(C(d, physics::kMu0),
                hn::Add(hn::Mul(C(d, kFluxGuardMsFactor), c.rod(kFluxMs, i)), hn::Abs(s.f[kH][i])));
    fails.mark(d, hn::Not(hn::Le(hn::Abs(s.f[kB][i]), bound)), kFailFlux, s.f[kB][i], i, t, bound);
  }
}

// The lanes' failure records (kFail ...) in and out of a chunk.
template <class D>
HWY_INLINE Fails<D> load_fails(const Chunk<D>& c) {
  return {hn::Ne(c.glob(kFail), hn::Zero(c.d)),
          c.glob(kFail),
          c.glob(kFailValue),
          c.glob(kFailRod),
          c.glob(kFailT),
          c.glob(kFailBound)};
}
template <class D>
HWY_INLINE void store_fails(const Chunk<D>& c, const Fails<D>& f) {
  hn::StoreU(f.code, c.d, c.glob_at(kFail));
  hn::StoreU(f.value, c.d, c.glob_at(kFailValue));
  hn::StoreU(f.rod, c.d, c.glob_at(kFailRod));
  hn::StoreU(f.t, c.d, c.glob_at(kFailT));
  hn::StoreU(f.bound, c.d, c.glob_at(kFailBound));
}

// The rods' state of lanes [j, j + Lanes(d)), loaded field by field. A full step writes its
// outputs (mu_r, E, lambda, tau, phi, K_osc, B) before it reads them: with outputs = false they
// are not loaded (a lane that fails keeps them in memory: store_rods).
template <class D>
HWY_INLINE RodStates<D> load_rods(const Chunk<D>& c, bool outputs) {
  RodStates<D> s;
  for (int f = 0; f < kRodStateCount; ++f) {
    if (!outputs &&
        (f == kMuR || f == kE || f == kLambda || f == kTau || f == kPhi || f == kKOsc || f == kB))
      continue;
    for (int i = 0; i < c.n; ++i) s.f[f][i] = c.rod(f, i);
  }
  return s;
}

// Stores the rods' state back where `keep` holds (a lane that failed keeps its old state).
template <class D>
HWY_INLINE void store_rods(const Chunk<D>& c, const RodStates<D>& s, Mk<D> keep) {
  for (int f = 0; f < kRodStateCount; ++f)
    for (int i = 0; i < c.n; ++i) hn::BlendedStore(s.f[f][i], keep, c.d, c.rod_at(f, i));
}

// One step of lanes [j, j + Lanes(d)): load, the stages, store where the lane is still alive
// (a lane that fails keeps its state before the step, as simulate() records it).
template <class Law, class D>
HWY_INLINE void step_chunk(D d, LaneData& L, std::size_t j, const StepInputs& in) {
  const Chunk<D> c(d, L, j);
  RodStates<D> s = load_rods(c, false);
  V<D> g[kGlobalStateCount];
  for (int f = 0; f < kGlobalStateCount; ++f) g[f] = c.glob(f);
  Fails<D> fails = load_fails(c);
  const Mk<D> alive = hn::Not(fails.failed);
  const V<D> I = hn::LoadU(d, in.current_A + j), h = hn::LoadU(d, in.dt_s + j);
  const V<D> t1 = hn::Add(g[kT], h);  // step()'s t1 = s.t_s + h
  LaneNewton<Law, D> mg(c, s, I, c.glob(kPmScale), t1, fails);
  magnetic_state(mg, h, false);
  for (int i = 0; i < c.n; ++i) {
    fails.check(d, s.f[kH][i], C(d, 1e9), kFailH, i, t1);
    fails.check(d, s.f[kM][i], hn::Mul(C(d, 1.5), c.rod(kMsTMag, i)), kFailM, i, t1);
  }
  mechanics(c, s, h, t1, fails);
  mount_and_outputs(c, s, g, h, t1, fails);
  g[kT] = hn::LoadU(d, in.t1_s + j);
  g[kCurrent] = I;
  run_loop_checks(c, s, g, g[kT], fails);
  const Mk<D> keep = hn::AndNot(fails.failed, alive);  // alive and not failed now
  law_commit(c, mg.trial, keep);
  store_rods(c, s, keep);
  for (int f = 0; f < kGlobalStateCount; ++f) hn::BlendedStore(g[f], keep, d, c.glob_at(f));
  store_fails(c, fails);
}

// One increment of make_state's ramp (model/step.cpp, quasi_static_magnetic_update on the
// consistent state) for lanes [j, j + Lanes(d)): the magnetic state at rest at the current and
// the magnets' scale of the increment; a lane that fails keeps its state.
template <class Law, class D>
HWY_INLINE void ramp_chunk(D d, LaneData& L, std::size_t j, const StepInputs& in) {
  const Chunk<D> c(d, L, j);
  RodStates<D> s = load_rods(c, true);
  Fails<D> fails = load_fails(c);
  const Mk<D> alive = hn::Not(fails.failed);
  const V<D> I = hn::LoadU(d, in.current_A + j), pm = hn::LoadU(d, in.pm_scale + j);
  const V<D> one = C(d, 1.0), t = hn::Zero(d);
  LaneNewton<Law, D> mg(c, s, I, pm, t, fails);
  magnetic_state(mg, one, true);
  const Mk<D> keep = hn::AndNot(fails.failed, alive);
  law_commit(c, mg.trial, keep);
  store_rods(c, s, keep);
  store_fails(c, fails);
}

template <class Law, class D>
HWY_INLINE void chunk(D d, LaneData& L, std::size_t j, const StepInputs& in) {
  if (in.quasi_static)
    ramp_chunk<Law>(d, L, j, in);
  else
    step_chunk<Law>(d, L, j, in);
}

// The chunks of one law. The lanes left after the full chunks take a vector of half the width
// where they fit in it, not a full one of padding (the Jiles-Atherton law; the Preisach law's
// kernel is compiled for the full width and width 1 only: a third instance per SIMD target
// cost 30 s of the CI's compile).
template <class Law>
void step_law(LaneData& L, const StepInputs& in, bool width_one) {
  if (width_one) {
    const hn::CappedTag<double, 1> d1;
    for (std::size_t j = 0; j < L.npad; ++j) chunk<Law>(d1, L, j, in);
    return;
  }
  const hn::ScalableTag<double> d;
  const std::size_t w = hn::Lanes(d);
  std::size_t j = 0;
  for (; j + w <= L.n; j += w) chunk<Law>(d, L, j, in);
  const std::size_t rest = L.n - j;
  if (rest == 0) return;
  if constexpr (std::is_same_v<Law, JilesAthertonLanes>) {
    if (w >= 4 && rest <= w / 2) {
      chunk<Law>(hn::CappedTag<double, HWY_MAX(1, HWY_LANES(double) / 2)>(), L, j, in);
      return;
    }
  }
  chunk<Law>(d, L, j, in);
}

// All lanes, in chunks of the target's width (or of 1: the reference instance), by the law the
// batch holds (preisach_lanes-inl.h for the Preisach law's hooks).
void StepAll(LaneData& L, const StepInputs& in, bool width_one) {
  if (L.st.preisach)
    step_law<PreisachLanes>(L, in, width_one);
  else
    step_law<JilesAthertonLanes>(L, in, width_one);
}

// lane_data.hpp, mechanics_laws_dispatch: the laws of mechanics() and mount_and_outputs() on
// given inputs (a rod whose chain is itself; the mount's decay starts where the rod's does).
void MechanicsLaws(const double* in, double* out, std::size_t n) {
  using N = Lanes<hn::ScalableTag<double>>;
  const hn::ScalableTag<double> d;
  for (std::size_t j = 0; j < n; j += hn::Lanes(d)) {
    auto at = [&](int f) -> N { return hn::LoadU(d, in + static_cast<std::size_t>(f) * n + j); };
    auto put = [&](int f, N v) { hn::StoreU(v.v, d, out + static_cast<std::size_t>(f) * n + j); };
    const laws::DeltaETermsT<N> dE{at(kPiInvEs), at(kPiRot), at(kPiCoupling), at(kPiMu0Ms2),
                                   at(kPiS)};
    laws::ExpPointT<N> prestress{at(kPiPrestressY), at(kPiPrestressE)};
    const laws::RodMechanicsT<N> k = laws::rod_mechanics<N>(
        at(kPiM), at(kPiInvMsTE), dE, at(kPiInvMsStrain), at(kPiLambdaS), at(kPiSigmaP),
        N(4.0) * at(kPiSigmaP) / at(kPiLambdaS), at(kPiArea), at(kPiAreaOverLength),
        at(kPiLengthOverArea), at(kPiJointCompliance), prestress);
    const N compliance[1] = {k.compliance_m_per_N};
    const int self[1] = {0};
    const N k_load = laws::chain_stiffness<N>(at(kPiFixedCompliance), compliance, self, 1);
    const N K = laws::mid_step_stiffness<N>(at(kPiK0), k.k_rod_N_per_m, k_load);
    N x = at(kPiX), v = at(kPiV), z = at(kPiZ), zv = at(kPiZv);
    laws::ExpPointT<N> decay{at(kPiDecayY), at(kPiDecayE)}, mount = decay;
    laws::oscillator_step<N>(at(kPiMass), at(kPiInvMass), at(kPiDamping), K, at(kPiF0), k.F_N,
                             at(kPiH), x, v, decay);
    laws::base_excited_step<N>(at(kPiMass), at(kPiInvMass), at(kPiDamping), K, at(kPiQ0), at(kPiQ1),
                               at(kPiH), z, zv, mount);
    const N values[kLawProbeOutCount] = {k.E_Pa,
                                         k.lambda,
                                         k.F_N,
                                         k.k_rod_N_per_m,
                                         k.compliance_m_per_N,
                                         prestress.y,
                                         prestress.e,
                                         k_load,
                                         K,
                                         x,
                                         v,
                                         decay.y,
                                         decay.e,
                                         z,
                                         zv,
                                         mount.y,
                                         mount.e};
    for (int f = 0; f < kLawProbeOutCount; ++f) put(f, values[f]);
  }
}

int WidthOf() { return static_cast<int>(hn::Lanes(hn::ScalableTag<double>())); }

}  // namespace gmasim::lanes::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace gmasim::lanes {

HWY_EXPORT(StepAll);
HWY_EXPORT(WidthOf);
HWY_EXPORT(MechanicsLaws);

void mechanics_laws_dispatch(const double* in, double* out, std::size_t n) {
  HWY_DYNAMIC_DISPATCH(MechanicsLaws)(in, out, n);
}

void step_dispatch(LaneData& d, const StepInputs& in, bool width_one) {
  HWY_DYNAMIC_DISPATCH(StepAll)(d, in, width_one);
}

int dispatch_lanes() { return HWY_DYNAMIC_DISPATCH(WidthOf)(); }

const char* dispatch_target_name() {
  // The best target this CPU supports among those compiled in (what HWY_DYNAMIC_DISPATCH
  // calls): SupportedAndGeneratedTargets() lists them best first.
  const auto targets = hwy::SupportedAndGeneratedTargets();
  return targets.empty() ? "none" : hwy::TargetName(targets.front());
}

}  // namespace gmasim::lanes
#endif  // HWY_ONCE
