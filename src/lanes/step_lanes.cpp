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

// The lanes' context of the mechanical stages (gmasim/physics/mechanics_stage-inl.h, the one
// text the scalar step also runs: laws::strain_stage, oscillators_stage, sensor_mount_stage): the
// rods' state in RodStates, the sensor mount's in the global fields g, their constants in the
// LaneData, a failure recorded in the lane's record (Fails).
template <class D>
struct LaneMechanics {
  using N = Lanes<D>;
  const Chunk<D>& c;
  RodStates<D>& s;
  V<D>* g;
  V<D> t1;
  Fails<D>& fails;

  HWY_INLINE int rods() const { return c.n; }
  HWY_INLINE laws::RodStrainT<N> strain_state(int i) const {
    return {s.f[kF][i], s.f[kKRod][i],   s.f[kKLoad][i],
            s.f[kE][i], s.f[kLambda][i], {s.f[kPrestressY][i], s.f[kPrestressE][i]}};
  }
  HWY_INLINE void store_strain(int i, const laws::RodStrainT<N>& v) const {
    s.f[kF][i] = v.F.v;
    s.f[kKRod][i] = v.k_rod.v;
    s.f[kE][i] = v.E.v;
    s.f[kLambda][i] = v.lambda.v;
    s.f[kPrestressY][i] = v.prestress.y.v;
    s.f[kPrestressE][i] = v.prestress.e.v;
  }
  HWY_INLINE laws::RodOscillatorT<N> oscillator(int i) const {
    return {s.f[kF][i],
            s.f[kKRod][i],
            s.f[kKLoad][i],
            s.f[kKOsc][i],
            s.f[kX][i],
            s.f[kV][i],
            {s.f[kOscDecayY][i], s.f[kOscDecayE][i]}};
  }
  HWY_INLINE void store_oscillator(int i, const laws::RodOscillatorT<N>& v) const {
    s.f[kKLoad][i] = v.k_load.v;
    s.f[kKOsc][i] = v.K_osc.v;
    s.f[kX][i] = v.x.v;
    s.f[kV][i] = v.v.v;
    s.f[kOscDecayY][i] = v.osc_decay.y.v;
    s.f[kOscDecayE][i] = v.osc_decay.e.v;
  }
  HWY_INLINE N x(int i) const { return s.f[kX][i]; }
  HWY_INLINE N M(int i) const { return s.f[kM][i]; }
  HWY_INLINE laws::RodMechanicsInputsT<N> inputs(int i) const {
    return {
        c.rod(kInvMsTE, i),
        {c.rod(kInvEs, i), c.rod(kRot, i), c.rod(kCoupling, i), c.rod(kMu0Ms2, i), c.rod(kSdE, i)},
        c.rod(kInvMsStrain, i),
        c.rod(kSigmaP, i),
        c.rod(kFourSpOverLs, i),
        c.rod(kArea, i),
        c.rod(kAreaOverLength, i),
        c.rod(kLengthPerArea, i),
        c.rod(kJointCompl, i)};
  }
  HWY_INLINE N lambda_s() const { return c.glob(kLambdaS); }
  HWY_INLINE N fixed_compliance(int i) const { return c.rod(kFixedCompl, i); }
  HWY_INLINE const int* chain(int i) const {
    return c.L.st.chain[static_cast<std::size_t>(i)].data();
  }
  HWY_INLINE int chain_count(int i) const {
    return c.L.st.chain_count[static_cast<std::size_t>(i)];
  }
  HWY_INLINE N mass_osc(int i) const { return c.rod(kMassOsc, i); }
  HWY_INLINE N inv_mass_osc(int i) const { return c.rod(kInvMassOsc, i); }
  HWY_INLINE N damping_osc(int i) const { return c.rod(kDampOsc, i); }
  HWY_INLINE void check_x(int i, N x) const { fails.check(c.d, x.v, C(c.d, 1.0), kFailX, i, t1); }
  HWY_INLINE bool mount() const { return c.L.st.mount; }
  HWY_INLINE bool mount_on_output() const { return c.L.st.mount_on_output; }
  HWY_INLINE N momentum_mass(int i) const { return c.rod(kMomMass, i); }
  HWY_INLINE N actuator_mass() const { return c.glob(kActMass); }
  HWY_INLINE N mount_mass() const { return c.glob(kMountMass); }
  HWY_INLINE N mount_inv_mass() const { return c.glob(kMountInvMass); }
  HWY_INLINE N mount_damping() const { return c.glob(kMountC); }
  HWY_INLINE N mount_stiffness() const { return c.glob(kMountK); }
  HWY_INLINE laws::MountStateT<N> mount_state() const {
    return {g[kZ], g[kZv], g[kQ], {g[kMountDecayY], g[kMountDecayE]}};
  }
  HWY_INLINE void store_mount(const laws::MountStateT<N>& v) const {
    g[kZ] = v.z.v;
    g[kZv] = v.zv.v;
    g[kQ] = v.q.v;
    g[kMountDecayY] = v.decay.y.v;
    g[kMountDecayE] = v.decay.e.v;
  }
  HWY_INLINE void check_z(N z) const { fails.check(c.d, z.v, C(c.d, 1.0), kFailZ, -1, t1); }
};

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

// The lanes' stages for laws::run_stages (gmasim/physics/stage_order-inl.h: the scalar step's
// order, written once), over the rods' state s and the global fields g of one chunk.
template <class Law, class D>
struct LaneStages {
  using N = Lanes<D>;
  const Chunk<D>& c;
  RodStates<D>& s;
  V<D>* g;
  Fails<D>& fails;
  const StepInputs& in;
  V<D> I, h, t1;
  LaneNewton<Law, D> mg;  // the magnetic state's solve; its trials are committed after the step
  LaneMechanics<D> k;
  N F0[kMaxRods], K0[kMaxRods], compliance[kMaxRods];

  LaneStages(const Chunk<D>& c_, RodStates<D>& s_, V<D>* g_, Fails<D>& f_, const StepInputs& in_)
      : c(c_),
        s(s_),
        g(g_),
        fails(f_),
        in(in_),
        I(hn::LoadU(c_.d, in_.current_A + c_.j)),
        h(hn::LoadU(c_.d, in_.dt_s + c_.j)),
        t1(hn::Add(g_[kT], h)),  // step()'s t1 = s.t_s + h
        mg(c_, s_, I, c_.glob(kPmScale), t1, f_),
        k{c_, s_, g_, t1, f_} {}
  // Stage 0: t1 (above); the lanes book no ledgers.
  HWY_INLINE void begin() {}
  // Stage 1 (stage_magnetic): the consistent state, then the guards on H and M.
  HWY_INLINE void magnetic() {
    magnetic_state(mg, h, false);
    for (int i = 0; i < c.n; ++i) {
      fails.check(c.d, s.f[kH][i], C(c.d, 1e9), kFailH, i, t1);
      fails.check(c.d, s.f[kM][i], hn::Mul(C(c.d, 1.5), c.rod(kMsTMag, i)), kFailM, i, t1);
    }
  }
  // Stages 2 and 3 (stage_strain, stage_mechanics): the scalar step's text.
  HWY_INLINE void strain() { laws::strain_stage<N>(k, F0, K0, compliance); }
  HWY_INLINE void mechanics() {
    laws::oscillators_stage<N>(k, F0, K0, compliance, N(h));
    laws::sensor_mount_stage<N>(k, laws::stack_displacement<N>(k), N(h));
  }
  HWY_INLINE void end_time() {
    g[kT] = hn::LoadU(c.d, in.t1_s + c.j);
    g[kCurrent] = I;
  }
  // Stage 4 (finish_outputs): y = y_stack (eq. 20) + the probe's deflection (+ x_T), B of the
  // coil and of each rod.
  HWY_INLINE void outputs() {
    const D d = c.d;
    const Structure& st = c.L.st;
    V<D> y = laws::stack_displacement<N>(k).v;
    g[kYStack] = y;
    if (st.mount) y = st.mount_on_output ? g[kZ] : hn::Add(y, hn::Sub(g[kZ], g[kQ]));
    if (st.xT_in_output) y = hn::Add(y, c.glob(kXT));
    g[kY] = y;
    V<D> phi = hn::Zero(d);
    for (int i = 0; i < st.sensor_count; ++i)
      phi = hn::Add(phi, s.f[kPhi][st.sensor_rods[static_cast<std::size_t>(i)]]);
    g[kBSensor] = hn::Div(phi, c.glob(kSensorArea));
    for (int i = 0; i < c.n; ++i) s.f[kB][i] = hn::Mul(s.f[kPhi][i], c.rod(kInvArea, i));
  }
  HWY_INLINE void ledger() {}  // none: a run with the ledgers on is not put in lanes
};

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
  LaneStages<Law, D> st(c, s, g, fails, in);
  laws::run_stages(st);
  run_loop_checks(c, s, g, g[kT], fails);
  const Mk<D> keep = hn::AndNot(fails.failed, alive);  // alive and not failed now
  law_commit(c, st.mg.trial, keep);
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
