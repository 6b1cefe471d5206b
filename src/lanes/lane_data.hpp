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

// Per rod and lane: the step's state (RodState's numbers), then the constants it reads
// (RodConditions, Material, the circuit's rod branch).
enum RodField : int {
  kH,
  kMirr,
  kM,
  kHc,
  kHprev,
  kMprev,
  kHprev2,
  kMprev2,
  kX,
  kV,
  kF,
  kMuR,
  kE,
  kLambda,
  kTau,
  kPhi,
  kKRod,
  kKLoad,
  kKOsc,
  kB,
  kAnX,   // the law's last evaluation, H_e / a (RodState::an_x; NaN: none)
  kAnL,   // L there (RodState::an_L)
  kAnDL,  // L' there (RodState::an_dL)
  kRodStateCount,
  kLength = kRodStateCount,
  kArea,
  kMsTMag,
  kInvEs,
  kRot,
  kCoupling,
  kMu0Ms2,
  kSdE,
  kJaA,
  kJaAlpha,
  kJaC,
  kJaK,
  kKappa,
  kRs,
  kMassOsc,
  kMomMass,
  kDampOsc,
  kFixedCompl,
  kSigmaP,
  kCoilTurns,
  kPmMmf,
  kStrainBound,
  kFluxMs,
  kJaInvA,          // 1 / a (the scalar law's inv_a)
  kLengthPerArea,   // l / A (the consistent step's l_A)
  kInvArea,         // 1 / A
  kInvMassOsc,      // 1 / m of the rod's oscillator (oscillator_step's inv_m)
  kJaInvK,          // 1 / k (JaMoveStart::inv_k)
  kInvMsTE,         // 1 / M_s^T of eq. (13) (RodConditions::inv_MsT_E_m_per_A)
  kInvMsStrain,     // 1 / M_s of eq. (11) (RodConditions::inv_Ms_strain_m_per_A)
  kAreaOverLength,  // A / l (eq. 17)
  kFourSpOverLs,    // 4 sigma_p / lambda_s (eq. 11's 2 sigma_p / sigma_s times E)
  kRodFieldCount
};

// Per lane: the State's scalars, the constants, and the diagnosis of a diverged lane.
enum GlobalField : int {
  kT,
  kCurrent,
  kY,
  kYStack,
  kQ,
  kZ,
  kZv,
  kBSensor,
  kGlobalStateCount,
  kPmScale = kGlobalStateCount,
  kXT,
  kMountMass,
  kMountK,
  kMountC,
  kActMass,
  kLambdaS,
  kSensorArea,
  kMountInvMass,  // 1 / m of the sensor mount's oscillator
  kFail,
  kFailValue,
  kFailRod,
  kFailT,
  kFailBound,
  kGlobalFieldCount
};

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
// The target the dispatcher chose and its vector width in doubles.
const char* dispatch_target_name();
int dispatch_lanes();

}  // namespace gmasim::lanes
