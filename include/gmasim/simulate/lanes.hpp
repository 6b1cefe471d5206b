// Batched SIMD lanes (issue 22, docs/lanes.md): one step advances W independent simulations
// at once -- different temperatures, currents, frequencies or parameter vectors of models
// with the same structure -- with the instruction set chosen at run time for the CPU
// (Highway's dynamic dispatch: AVX-512, AVX2, SSE4 or the portable fallback). Each lane
// does what step() followed by run_loop()'s checks does (model/step.cpp), with its own
// Newton convergence (masked), and records its own divergence instead of throwing.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

namespace lanes {
struct LaneData;
}

// Whether lanes can advance model m: the Jiles-Atherton or the Preisach law (docs/lanes.md,
// "Preisach lanes"; a batch holds one law), the consistent magnetic state, a
// circuit on the low-rank path (gmasim/circuit.hpp) with the flux sensor on rod branches, at
// most 8 rods. `why` receives the reason when not.
bool lanes_supported(const Model& m, std::string* why = nullptr);

// The SIMD target the dispatcher chose on this CPU ("AVX3", "AVX2", ...) and its width in
// doubles (the lanes one vector instruction advances).
std::string lanes_target();
int lanes_width();

class LaneBatch {
 public:
  // One lane per (model, conditions, state); the models share the structure of models[0]
  // (rods, circuit topology, load chains, sensor mount, options; InputError otherwise).
  // The states are where each lane starts (make_state, or a state step() advanced); the
  // pointers need not outlive the constructor. Buffers are sized here, once.
  LaneBatch(std::span<const Model* const> models, std::span<const Conditions* const> conditions,
            std::span<const State* const> states);
  ~LaneBatch();
  LaneBatch(LaneBatch&&) noexcept;
  LaneBatch& operator=(LaneBatch&&) noexcept;

  std::size_t size() const;
  // One step of every live lane: current at the step's end, step length and the grid's time
  // at its end (run_loop's t_k), size() values each. width_one runs the width-1 instance of
  // the same kernel (the reference a lane is compared with). Allocation-free.
  void step(std::span<const double> current_A, std::span<const double> dt_s,
            std::span<const double> t1_s, bool width_one = false);
  // One increment of make_state's quasi-static ramp (model/step.cpp: the magnetic state at
  // rest, no eddy lag) of every live lane, at the current and the magnets' scale given per
  // lane (size() values each). Allocation-free. A lane whose solve fails stops (diverged()).
  void rest_increment(std::span<const double> current_A, std::span<const double> pm_scale,
                      bool width_one = false);
  // Whether the lane stopped, and why: the DivergenceError text step() or run_loop() would
  // have thrown (time, rod, quantity, value). A stopped lane keeps its last good state.
  bool diverged(std::size_t lane) const;
  // How many lanes have stopped so far (a caller checks its lanes only when this grows).
  std::size_t diverged_count() const;
  // How many of the live lanes' law evaluations (per rod and Newton iterate, summed over the
  // steps so far) solved eq. (9) fully: the Jiles-Atherton law's safeguard where the joint
  // Newton iterate is far from eq. (9) (|g| > 1e-3 M_s^T), as the scalar law's joint_trial does.
  std::size_t full_solves() const;
  // The consistent state's circuit solves so far: summed over the live lanes that needed one
  // (as State::newton_solves counts them), and per vector of lanes the kernel ran (a vector
  // solves while any of its lanes needs it).
  std::size_t newton_solves() const;
  std::size_t vector_solves() const;
  std::string error(std::size_t lane) const;
  // The lane's state as step() leaves it, into s (sized by make_state for the lane's model:
  // no allocation).
  void unpack(std::size_t lane, State& s) const;
  // One row of simulate()'s series (src/simulate/run.cpp, record(): the same columns and
  // values) from the lane's state, without unpacking it; thermal_expansion_m is the lane's
  // Conditions::thermal_expansion_m.
  void record(std::size_t lane, double thermal_expansion_m, TimeSeries& ts) const;
  // The same row into row[0 .. record_width()): what a caller stages before appending a block of
  // rows column by column (many lanes appending to their columns step by step write to as many
  // page-aligned streams at once, which the L1 cache cannot hold).
  void record_row(std::size_t lane, double thermal_expansion_m, double* row) const;
  std::size_t record_width() const;
  // The lane's outputs without unpacking: y and B of the coil (State::y_m, B_T), and one
  // rod's displacement x.
  double y_m(std::size_t lane) const;
  double B_T(std::size_t lane) const;
  double x_m(std::size_t lane, int rod) const;
  // Sets the lane's State::t_s (a grid that starts again, as run_loop() does at its t0).
  void set_time(std::size_t lane, double t_s);

 private:
  std::unique_ptr<lanes::LaneData> d_;
  std::vector<std::string> rod_names_;
  std::vector<double> in_current_, in_dt_, in_t1_, in_pm_;  // padded inputs
  void pad_inputs(std::span<const double> a, std::vector<double>& to) const;
};

// make_state() for many (model, conditions, current at t = 0) at once: make_state's ramp in
// lanes (kRestRampSteps increments, gmasim/model/step_stages.hpp), then each state settled at
// rest as make_state settles it; equal to make_state to the lanes' rounding. The models share a
// structure and are lanes_supported (LaneBatch). A lane whose ramp fails runs make_state itself,
// which throws the DivergenceError make_state throws.
std::vector<State> make_states(std::span<const Model* const> models,
                               std::span<const Conditions* const> conditions,
                               std::span<const double> current_A);

// simulate() for many settings of one model: the settings the lanes can run (no
// self-heating, no energy ledger, a model lanes_supported) advance together in lanes,
// grouped by their step count; the others run simulate(). Results in the order of the
// settings; the same validation and errors as simulate(). metrics_only: a lane keeps only what
// its metrics read -- t, the current, y and B over its metrics window (the last period) and the
// row before it -- and its metrics are those of the full record (what a sweep keeps); the
// series' columns are left empty. Settings that do not take the lanes run simulate_metrics_only.
std::vector<Result> simulate_lanes(const Model& m, std::span<const SimulationSettings> settings,
                                   bool metrics_only = false);

}  // namespace gmasim
