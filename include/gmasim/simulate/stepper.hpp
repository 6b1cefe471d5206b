// Stepper: one actuator simulated sample by sample, for real-time loops and co-simulation
// (a controller that computes the next coil current from the last output). The session that
// the C API (gmasim/capi/gmasim_c.h) and the Python gmasim.Stepper wrap: a model, the conditions at
// one temperature, the state, a fixed time step, and a divergence latch (docs/c_api.md).
#pragma once

#include <memory>
#include <string>

#include "gmasim/model/model.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {

// Time steps a Stepper accepts [s]: kMinStepDt_s <= dt_s <= kMaxStepperDt_s
// (gmasim/model/validate.hpp). step() is exact for the eddy-current and mechanical updates, but a
// step longer than a millisecond resolves neither the eddy time constants nor the 7-20 kHz
// mechanical modes, and one shorter than 1e-12 s no longer holds the state (docs/model.md, "Time
// step").
inline constexpr double kMaxStepperDt_s = kMaxStepDt_s;

class Stepper {
 public:
  // The actuator at temperature_C [degC] (make_conditions checks it against absolute zero and
  // the Curie point), at rest under current_A [A] (|current_A| <= kMaxCurrent_A), stepped by
  // dt_s [s] (0 < dt_s <= kMaxStepperDt_s). Throws InputError naming the value and the rule;
  // DivergenceError if the initial equilibrium cannot be found. Allocates.
  Stepper(std::shared_ptr<const Model> model, double temperature_C, double dt_s,
          double current_A = 0.0, const Freeze& freeze = {});

  // Advances by one step of dt_s to t = (steps() + 1) dt_s with current_A [A] the coil current at
  // the end of the step (the convention of simulate()); returns the output displacement y [m].
  // Allocation-free on success. Throws InputError for a non-finite or too large current (the
  // state is untouched) and DivergenceError when the step diverges; after a divergence every
  // step() throws DivergenceError again ("...: reset() before stepping again") until reset().
  double step(double current_A);

  // Back to t = 0 at rest under current_A [A] at the current temperature; clears the divergence
  // latch. Allocates (make_state). On an exception the stepper is unchanged.
  void reset(double current_A = 0.0);

  // Recomputes the conditions at temperature_C [degC] and keeps the state (a temperature change
  // between two steps). Allocates (make_conditions). On an exception the stepper is unchanged.
  void set_temperature(double temperature_C);

  const Model& model() const { return *model_; }
  const std::shared_ptr<const Model>& model_ptr() const { return model_; }
  const Conditions& conditions() const { return conditions_; }
  const State& state() const { return state_; }
  double dt_s() const { return dt_s_; }
  double temperature_C() const { return conditions_.temperature_C; }
  long steps() const { return steps_; }  // steps taken since creation or reset()
  double t_s() const { return state_.t_s; }
  double y_m() const { return state_.y_m; }
  double B_T() const { return state_.B_T; }
  int rod_count() const { return model_->rod_count(); }
  // True after a step diverged, until reset(); divergence_message() is that step's error.
  bool diverged() const { return diverged_; }
  const std::string& divergence_message() const { return divergence_message_; }

 private:
  std::shared_ptr<const Model> model_;
  Freeze freeze_;
  Conditions conditions_;
  State state_;
  double dt_s_ = 0.0;
  long steps_ = 0;
  bool diverged_ = false;
  std::string divergence_message_;
  double divergence_t_s_ = 0.0;
};

}  // namespace gmasim
