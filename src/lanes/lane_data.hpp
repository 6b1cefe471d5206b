// The lanes' structure-of-arrays layout (docs/lanes.md, "Data layout"): every per-simulation
// number is an array over the lanes, so that one SIMD load reads the same quantity of W
// simulations. Internal to src/lanes; the public face is gmasim/lanes.hpp.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "lanes/lane_array.hpp"
#include "lanes/preisach_lane_data.hpp"

namespace gmasim::lanes {

inline constexpr int kMaxRods = 8;
// Lanes are padded to a multiple of the widest vector (AVX-512: 8 doubles); a padding lane
// repeats the last lane and is never read back.
inline constexpr std::size_t kPad = 8;

// The fields, each in one table: its name and where pack.cpp reads it (LaneBatch::unpack writes
// a state field back to the same place). The enums below and pack/unpack are generated from
// these tables, so a field is added in one line. A state field is what the step changes (loaded
// into registers for the step, stored after it), a constant what it only reads.
//
// Per rod and lane: the step's state (RodState's numbers, r), ...
#define GMASIM_LANE_ROD_STATE(X)                                                           \
  X(kH, r.H_A_per_m)                                                                       \
  X(kMirr, r.Mirr_A_per_m)                                                                 \
  X(kM, r.M_A_per_m)                                                                       \
  X(kHc, r.Hc_A_per_m)                                                                     \
  X(kHprev, r.H_prev_A_per_m)                                                              \
  X(kMprev, r.M_prev_A_per_m)                                                              \
  X(kHprev2, r.H_prev2_A_per_m)                                                            \
  X(kMprev2, r.M_prev2_A_per_m)                                                            \
  X(kX, r.x_m)                                                                             \
  X(kV, r.v_m_per_s)                                                                       \
  X(kF, r.F_N)                                                                             \
  X(kMuR, r.mu_r)                                                                          \
  X(kE, r.E_Pa)                                                                            \
  X(kLambda, r.lambda)                                                                     \
  X(kTau, r.tau_s)                                                                         \
  X(kPhi, r.phi_Wb)                                                                        \
  X(kKRod, r.k_rod_N_per_m)                                                                \
  X(kKLoad, r.k_load_N_per_m)                                                              \
  X(kKOsc, r.K_osc_N_per_m)                                                                \
  X(kB, r.B_T)                                                                             \
  X(kAnX, r.an_x)                   /* the law's last evaluation, H_e / a (NaN: none) */   \
  X(kAnL, r.an_L)                   /* L there */                                          \
  X(kAnDL, r.an_dL)                 /* L' there */                                         \
  X(kPrestressY, r.prestress_exp.y) /* eq. (11)'s tanh anchor (physics::exp_near) */       \
  X(kPrestressE, r.prestress_exp.e)                                                        \
  X(kOscDecayY, r.osc_decay.y) /* the oscillator's last e^(tau/2) (physics::exp_cached) */ \
  X(kOscDecayE, r.osc_decay.e)                                                             \
  X(kJaLangevinY, r.ja_exp.langevin.y) /* the JA law's anchors (RodState::ja_exp) */       \
  X(kJaLangevinE, r.ja_exp.langevin.e)                                                     \
  X(kJaLagY, r.ja_exp.lag.y)                                                               \
  X(kJaLagE, r.ja_exp.lag.e)
// ... then the constants it reads (RodConditions rc, Material m.material, the circuit's rod
// branch br; q = M_s^T / M_s of the strain guard).
#define GMASIM_LANE_ROD_CONSTANTS(X)                                                     \
  X(kLength, rc.length_m)                                                                \
  X(kArea, rc.area_m2)                                                                   \
  X(kMsTMag, rc.MsT_mag)                                                                 \
  X(kInvEs, rc.dE.inverse_Es_per_Pa)                                                     \
  X(kRot, rc.dE.rotation_compliance_per_Pa)                                              \
  X(kCoupling, rc.dE.coupling)                                                           \
  X(kMu0Ms2, rc.dE.mu0_Ms2_over_chi_m_J_per_m3)                                          \
  X(kSdE, rc.dE.S_J_per_m3)                                                              \
  X(kJaA, rc.ja.a_A_per_m)                                                               \
  X(kJaAlpha, rc.ja.alpha)                                                               \
  X(kJaC, rc.ja.c)                                                                       \
  X(kJaK, rc.ja.k_A_per_m)                                                               \
  X(kKappa, rc.eddy_geometry_s_m_per_H)                                                  \
  X(kRs, rc.series_reluctance_per_H)                                                     \
  X(kMassOsc, rc.mass_osc_kg)                                                            \
  X(kMomMass, rc.momentum_mass_kg)                                                       \
  X(kDampOsc, rc.damping_osc_N_s_per_m)                                                  \
  X(kFixedCompl, rc.fixed_compliance_m_per_N)                                            \
  X(kJointCompl, rc.joint_compliance_m_per_N)                                            \
  X(kSigmaP, rc.sigma_p_Pa)                                                              \
  X(kCoilTurns, br.coil_turns)                                                           \
  X(kPmMmf, br.pm_mmf_At)                                                                \
  X(kStrainBound, kStrainGuardFactor* m.material.lambda_s* q* q)                         \
  X(kFluxMs, std::max(m.material.Ms_A_per_m, rc.MsT_mag))                                \
  X(kJaInvA, 1.0 / rc.ja.a_A_per_m)            /* the scalar law's inv_a */              \
  X(kLengthPerArea, rc.length_over_area_per_m) /* l / A (the consistent step's l_A) */   \
  X(kInvArea, 1.0 / rc.area_m2)                                                          \
  X(kInvMassOsc, rc.inv_mass_osc_per_kg)             /* 1 / m of the rod's oscillator */ \
  X(kJaInvK, 1.0 / rc.ja.k_A_per_m)                  /* JaMoveStart::inv_k */            \
  X(kInvMsTE, rc.inv_MsT_E_m_per_A)                  /* 1 / M_s^T of eq. (13) */         \
  X(kInvMsStrain, rc.inv_Ms_strain_m_per_A)          /* 1 / M_s of eq. (11) */           \
  X(kAreaOverLength, rc.area_over_length_m)          /* A / l (eq. 17) */                \
  X(kFourSpOverLs, rc.four_sigma_p_over_lambda_s_Pa) /* eq. (11)'s 4 sigma_p / lambda_s  \
                                                      */

// Per lane: the State's scalars (s), ...
#define GMASIM_LANE_GLOBAL_STATE(X)                                        \
  X(kT, s.t_s)                                                             \
  X(kCurrent, s.current_A)                                                 \
  X(kY, s.y_m)                                                             \
  X(kYStack, s.y_stack_m)                                                  \
  X(kQ, s.q_m)                                                             \
  X(kZ, s.z_m)                                                             \
  X(kZv, s.z_v_m_per_s)                                                    \
  X(kBSensor, s.B_T)                                                       \
  X(kMountDecayY, s.mount_decay.y) /* the sensor mount's, as kOscDecayY */ \
  X(kMountDecayE, s.mount_decay.e)
// ... and the constants (Conditions c, Model m; the flux sensor's area).
#define GMASIM_LANE_GLOBAL_CONSTANTS(X)        \
  X(kPmScale, c.pm_scale)                      \
  X(kXT, c.thermal_expansion_m)                \
  X(kMountMass, m.sensor_mount.mass_kg)        \
  X(kMountK, m.sensor_mount.stiffness_N_per_m) \
  X(kMountC, m.sensor_mount.damping_N_s_per_m) \
  X(kActMass, m.sensor_mount.actuator_mass_kg) \
  X(kLambdaS, m.material.lambda_s)             \
  X(kSensorArea, sensor_area)                  \
  X(kMountInvMass, m.sensor_mount.enabled ? 1.0 / m.sensor_mount.mass_kg : 0.0)

#define GMASIM_LANE_FIELD_NAME(name, source) name,
enum RodField : int {
  GMASIM_LANE_ROD_STATE(GMASIM_LANE_FIELD_NAME) kRodStateCount,
  kRodConstantsBefore = kRodStateCount - 1,
  GMASIM_LANE_ROD_CONSTANTS(GMASIM_LANE_FIELD_NAME) kRodFieldCount
};

// Per lane: the State's scalars, the constants, and the diagnosis of a diverged lane.
enum GlobalField : int {
  GMASIM_LANE_GLOBAL_STATE(GMASIM_LANE_FIELD_NAME) kGlobalStateCount,
  kGlobalConstantsBefore = kGlobalStateCount - 1,
  GMASIM_LANE_GLOBAL_CONSTANTS(GMASIM_LANE_FIELD_NAME) kFail,
  kFailValue,
  kFailRod,
  kFailT,
  kFailBound,
  kGlobalFieldCount
};
#undef GMASIM_LANE_FIELD_NAME

// What stopped a lane (kFail), in the order step() and run_loop() check (first one wins).
enum FailCode : int {
  kOk = 0,
  kFailNewton,
  kFailCircuit,
  kFailH,
  kFailM,
  kFailX,
  kFailZ,
  kFailY,
  kFailBSensor,
  kFailStrain,
  kFailDisplacement,
  kFailFlux
};

// What every lane shares: the model's structure.
struct Structure {
  int rods = 0;
  bool preisach = false;  // the Preisach law (LaneData::pre); the Jiles-Atherton law otherwise
  bool mount = false, xT_in_output = false;
  bool mount_on_output = false;  // options.sensor_mount_base = output
  int sensor_count = 0;
  std::array<int, kMaxRods> sensor_rods{};  // rods whose branches the flux sensor reads
  std::array<std::array<int, kMaxRods>, kMaxRods> chain{};  // eq. (18): rods in rod i's chain
  std::array<int, kMaxRods> chain_count{};
};

struct LaneData {
  Structure st;
  std::size_t n = 0, npad = 0;
  LaneArray g, r, cm;    // global, rod and circuit fields, each npad long (64-byte aligned)
  PreisachLaneData pre;  // the Preisach law's constants and stacks (empty otherwise)
  // How many joint trials of a live lane (not padding) solved eq. (9) fully (the law's safeguard,
  // ja_solve).
  std::size_t full_solves = 0;
  // The consistent state's circuit solves: per live lane that needed one (State::newton_solves
  // summed over the lanes), and per vector of lanes (what the kernel ran).
  std::size_t lane_solves = 0, vector_solves = 0;
  // The old state of one step (the kernel keeps a failing lane where it was).
  double* rod(int field, int i) {
    return r.data() +
           (static_cast<std::size_t>(field) * kMaxRods + static_cast<std::size_t>(i)) * npad;
  }
  double* glob(int field) { return g.data() + static_cast<std::size_t>(field) * npad; }
  // The low-rank circuit (gmasim/circuit.hpp): S(a, b), B^T psi_coil (a), B^T psi_pm (a).
  double* S(int a, int b) { return cm.data() + static_cast<std::size_t>(a * kMaxRods + b) * npad; }
  double* bt_coil(int a) {
    return cm.data() + static_cast<std::size_t>(kMaxRods * kMaxRods + a) * npad;
  }
  double* bt_pm(int a) {
    return cm.data() + static_cast<std::size_t>(kMaxRods * kMaxRods + kMaxRods + a) * npad;
  }
  void resize(std::size_t lanes) {
    n = lanes;
    npad = (lanes + kPad - 1) / kPad * kPad;
    g.assign(static_cast<std::size_t>(kGlobalFieldCount) * npad, 0.0);
    r.assign(static_cast<std::size_t>(kRodFieldCount) * kMaxRods * npad, 0.0);
    cm.assign(static_cast<std::size_t>(kMaxRods * kMaxRods + 2 * kMaxRods) * npad, 0.0);
  }
};

// One step's inputs per lane (npad long): the current at the end of the step, the step, and
// the grid's time at its end (run_loop's t_k).
struct StepInputs {
  const double* current_A;
  const double* dt_s;
  const double* t1_s;
  // make_state's ramp (quasi_static): one increment at rest, the magnets' MMF scaled by
  // pm_scale (per lane); dt_s and t1_s are not read.
  bool quasi_static = false;
  const double* pm_scale = nullptr;
};

// The kernel, dispatched to the best target of this CPU (src/lanes/step_lanes.cpp); width_one
// runs the width-1 instance of the same code (the reference each lane is compared with).
void step_dispatch(LaneData& d, const StepInputs& in, bool width_one);
// The mechanics laws alone (rod_mechanics, chain_stiffness, mid_step_stiffness, oscillator_step,
// base_excited_step) over n lanes (a multiple of 8), on the best target: for the test that each
// lane equals the scalar instance bit for bit (tests/test_laws_lanes.cpp). in[f * n + j] is
// field f (LawProbeIn) of lane j, out[f * n + j] field f of LawProbeOut.
enum LawProbeIn : int {
  kPiM,
  kPiInvMsTE,
  kPiInvEs,
  kPiRot,
  kPiCoupling,
  kPiMu0Ms2,
  kPiS,
  kPiInvMsStrain,
  kPiLambdaS,
  kPiSigmaP,
  kPiArea,
  kPiAreaOverLength,
  kPiLengthOverArea,
  kPiPrestressY,
  kPiPrestressE,
  kPiFixedCompliance,
  kPiJointCompliance,
  kPiK0,
  kPiMass,
  kPiInvMass,
  kPiDamping,
  kPiF0,
  kPiX,
  kPiV,
  kPiDecayY,
  kPiDecayE,
  kPiH,
  kPiQ0,
  kPiQ1,
  kPiZ,
  kPiZv,
  kLawProbeInCount
};
enum LawProbeOut : int {
  kPoE,
  kPoLambda,
  kPoF,
  kPoKRod,
  kPoCompliance,
  kPoPrestressY,
  kPoPrestressE,
  kPoKLoad,
  kPoK,
  kPoX,
  kPoV,
  kPoDecayY,
  kPoDecayE,
  kPoZ,
  kPoZv,
  kPoMountDecayY,
  kPoMountDecayE,
  kLawProbeOutCount
};
void mechanics_laws_dispatch(const double* in, double* out, std::size_t n);
// The target the dispatcher chose and its vector width in doubles.
const char* dispatch_target_name();
int dispatch_lanes();

}  // namespace gmasim::lanes
