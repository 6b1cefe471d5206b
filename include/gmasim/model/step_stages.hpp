// step() in named stages (issue 21; in the manner of MuJoCo's mj_fwdPosition / mj_fwdVelocity):
// each stage is a free function over the state, run in this order by step_law<Law>
// (src/model/step.cpp), and callable on its own by tests and other integrators.
//   stage_ledger_start   the ledgers' start values (gmasim/energy.hpp), when enabled
//   stage_magnetic<Law>  circuit (eq. 2-3, 23), eddy field (eq. 7) and the magnetisation law
//                        (eq. 9 for Jiles-Atherton): the consistent state's Newton solve, or the
//                        printed reading's explicit sequence
//   stage_strain         Delta-E modulus, magnetostriction, force and stiffness (eq. 11-14, 17)
//   stage_mechanics      each rod's oscillator over the step (eq. 15-16, 18) and the sensor mount
//   stage_outputs        the stack's output y (eq. 20-21) and the flux densities
//   stage_ledger         the step's energy ledgers (gmasim/energy.hpp), when enabled
// A stage's inputs are the state and what earlier stages left in StepScratch.
#pragma once

#include <array>

#include "gmasim/model/energy.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/stages.hpp"

namespace gmasim {

// What a step carries from its start to its later stages.
// The arrays are not cleared (a step's fixed cost): each stage writes rods 0..n-1 of what it
// leaves before a later stage reads them, start only where the ledgers are enabled.
struct StepScratch {
  double t1_s = 0.0;                 // the end of the step
  double current0_A = 0.0;           // the coil current at its start
  std::array<StepStart, 8> start;    // the ledgers' start values (stage_begin)
  std::array<double, 8> F0_N;        // each rod's force at the start (stage_strain)
  std::array<double, 8> K0_N_per_m;  // each rod's stiffness k_rod + k_load at the start
  std::array<double, 8> inv_k_rod;   // each rod's compliance 1/k_rod at the end (stage_strain)
};

// Sets t1_s and current0_A (and, with the ledgers enabled, their start values).
// A rod at rest: the histories of the consistent state's first guess (H and M one and two
// steps earlier) all equal the present values. Every place that puts a rod at rest calls it,
// so no history is left stale (make_state's settle_at_rest, the FRF's bias states).
inline void hold_history(RodState& r) {
  r.M_prev2_A_per_m = r.M_prev_A_per_m = r.M_A_per_m;
  r.H_prev2_A_per_m = r.H_prev_A_per_m = r.H_A_per_m;
}

// make_state's pieces (src/model/step.cpp), for callers that run its quasi-static ramp
// themselves (the lanes' make_states, gmasim/simulate/lanes.hpp): the state before the ramp
// (demagnetised rods, no field, buffers sized), the ramp's increments (increment k moves
// the current and the magnets' MMF to k / kRestRampSteps of their values) and the actuator
// settled at rest after it (histories, mechanics at rest, outputs).
// 400 increments: the rest state converges at second order in them and is within 5e-10 of the
// stroke of its limit here (4.8e-10 at 150 degC, 7.8e-11 at 20 degC: tests/test_model.cpp,
// RestState.RampConvergesAtSecondOrder). The ramp is a quarter of a batched identification
// evaluation's profile (200 steps a period, 2 periods); 200 increments would keep the rest
// state within 2e-9 of the stroke and three periods later leave no digit changed, but the
// calibration's search then takes another path (fit RMS 46.5 % against 46.4 %, the same
// claims) and moves some 40 quoted numbers of the docs: not done (docs/performance.md).
inline constexpr int kRestRampSteps = 400;
State demagnetised_state(const Model& m, const Conditions& c, double current_A);
void settle_at_rest(const Model& m, const Conditions& c, State& s);

void stage_begin(State& s, const StepInput& in, StepScratch& w);
template <class Law>
void stage_magnetic(const Model& m, const Conditions& c, State& s, const StepInput& in,
                    const StepScratch& w);
void stage_strain(const Model& m, const Conditions& c, State& s, StepScratch& w);
void stage_mechanics(const Model& m, const Conditions& c, State& s, const StepInput& in,
                     const StepScratch& w);
void stage_outputs(const Model& m, const Conditions& c, State& s);
void stage_ledger(const Model& m, const Conditions& c, State& s, const StepInput& in,
                  const StepScratch& w);

// The scalar step's stages for physics::run_stages (gmasim/physics/stage_order-inl.h: their order,
// written once), each the stage function above: step() runs them (step_law<Law>), and so may a
// test or another integrator.
template <class Law>
struct ScalarStages {
  const Model& m;
  const Conditions& c;
  State& s;
  const StepInput& in;
  StepScratch w;  // default-initialised, not zeroed (StepScratch: a step's fixed cost)
  ScalarStages(const Model& m_, const Conditions& c_, State& s_, const StepInput& in_)
      : m(m_), c(c_), s(s_), in(in_) {}
  void begin() { stage_begin(s, in, w); }
  void magnetic() { stage_magnetic<Law>(m, c, s, in, w); }
  void strain() { stage_strain(m, c, s, w); }
  void mechanics() { stage_mechanics(m, c, s, in, w); }
  void end_time() {
    s.t_s = w.t1_s;
    s.current_A = in.current_A;
  }
  void outputs() { stage_outputs(m, c, s); }
  void ledger() { stage_ledger(m, c, s, in, w); }
};

extern template void stage_magnetic<JilesAthertonLaw>(const Model&, const Conditions&, State&,
                                                      const StepInput&, const StepScratch&);
extern template void stage_magnetic<PreisachLaw>(const Model&, const Conditions&, State&,
                                                 const StepInput&, const StepScratch&);

}  // namespace gmasim
