// Stepper: the sample-by-sample session behind the C API and gmasim.Stepper.
#include "gmasim/simulate/stepper.hpp"

#include <fmt/format.h>

#include <limits>
#include <utility>

#include "gmasim/errors.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {
namespace {

const std::shared_ptr<const Model>& require_model(const std::shared_ptr<const Model>& m) {
  if (!m) throw InputError("Stepper: no model (null)");
  return m;
}

double checked_current(double current_A) {
  return require_in(current_A, -kMaxCurrent_A, kMaxCurrent_A, "coil current", "A");
}

double checked_dt(double dt_s) {
  require_positive(dt_s, "time step dt", "s");
  if (dt_s < kMinStepDt_s)
    throw InputError(fmt::format(
        "time step dt = {:g} s: must be >= {:g} s (the shortest step that holds the state; "
        "docs/model.md, \"Time step\")",
        dt_s, kMinStepDt_s));
  if (dt_s > kMaxStepperDt_s)
    throw InputError(fmt::format(
        "time step dt = {:g} s: must be <= {:g} s (a longer step resolves neither the eddy "
        "currents nor the mechanical modes)",
        dt_s, kMaxStepperDt_s));
  return dt_s;
}

}  // namespace

Stepper::Stepper(std::shared_ptr<const Model> model, double temperature_C, double dt_s,
                 double current_A, const Freeze& freeze)
    : model_(require_model(model)),
      freeze_(freeze),
      conditions_(make_conditions(*model_, temperature_C, freeze_)),
      dt_s_(checked_dt(dt_s)) {
  state_ = make_state(*model_, conditions_, checked_current(current_A));
  check_physical_validity(*model_, conditions_, state_, 0.0);
}

double Stepper::step(double current_A) {
  if (diverged_)
    throw DivergenceError(
        divergence_t_s_, "", "stepper state", std::numeric_limits<double>::quiet_NaN(),
        fmt::format("stopped by the earlier divergence '{}'; reset() before stepping again",
                    divergence_message_));
  checked_current(current_A);
  try {
    run_loop_step(*model_, conditions_, state_, steps_ + 1, dt_s_, current_A);
  } catch (const DivergenceError& e) {
    diverged_ = true;
    divergence_message_ = e.what();
    divergence_t_s_ = e.time_s;
    throw;
  }
  ++steps_;  // run_loop_step set t_s = steps_ dt, as simulate(): no drift from addition
  return state_.y_m;
}

void Stepper::reset(double current_A) {
  State fresh = make_state(*model_, conditions_, checked_current(current_A));
  check_physical_validity(*model_, conditions_, fresh, 0.0);
  state_ = std::move(fresh);
  steps_ = 0;
  diverged_ = false;
  divergence_message_.clear();
  divergence_t_s_ = 0.0;
}

void Stepper::set_temperature(double temperature_C) {
  Conditions c = make_conditions(*model_, temperature_C, freeze_);
  conditions_ = std::move(c);
}

}  // namespace gmasim
