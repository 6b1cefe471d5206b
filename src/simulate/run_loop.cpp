// The step grids of the run loop (gmasim/simulate/run_loop.hpp): where the step-count limit of
// every time-stepping is applied.
#include "gmasim/simulate/run_loop.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {
namespace {

void check_step(double dt_s, std::string_view what) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s))
    throw InputError(fmt::format("{}: time step {:g} s: must be finite and > 0", what, dt_s));
  if (dt_s < kMinStepDt_s)
    throw InputError(fmt::format(
        "{}: time step {:g} s: must be >= {:g} s (the shortest step that holds the state; "
        "docs/model.md, \"Time step\")",
        what, dt_s, kMinStepDt_s));
}

}  // namespace

namespace run_loop_detail {
void throw_not_finite(double t_s, const char* quantity, double value) {
  throw DivergenceError(t_s, "", quantity, value, "not finite");
}
}  // namespace run_loop_detail

long steps_to_resolve(double x, long at_least, std::string_view what) {
  return std::max(at_least, checked_ceil_count(x, kMaxSteps, what));
}

StepGrid StepGrid::uniform(double t0_s, double dt_s, double steps, std::string_view what) {
  StepGrid g;
  g.steps = checked_count(steps, kMaxSteps, what);
  check_step(dt_s, what);
  g.clock = StepClock::Uniform;
  g.t0_s = t0_s;
  g.dt_s = dt_s;
  return g;
}

StepGrid StepGrid::covering(double t0_s, double duration_s, double dt_s, std::string_view what) {
  const long steps = checked_step_count(duration_s, dt_s, what);
  return uniform(t0_s, dt_s, static_cast<double>(steps), what);
}

StepGrid StepGrid::spanning(double t0_s, double t1_s, double steps, std::string_view what) {
  StepGrid g;
  g.steps = checked_count(steps, kMaxSteps, what);
  if (g.steps < 1 || !std::isfinite(t0_s) || !std::isfinite(t1_s) || !(t1_s > t0_s))
    throw InputError(
        fmt::format("{}: {} steps from {:g} s to {:g} s: need at least one step "
                    "and an end after the start",
                    what, g.steps, t0_s, t1_s));
  g.clock = StepClock::Spanning;
  g.t0_s = t0_s;
  g.t1_s = t1_s;
  g.dt_s = (t1_s - t0_s) / static_cast<double>(g.steps);
  check_step(g.dt_s, what);
  return g;
}

StepGrid StepGrid::sampled(double t0_s, double sample_s, double samples, long substeps,
                           std::string_view what) {
  if (substeps < 1)
    throw InputError(fmt::format("{}: {} steps per sample: must be >= 1", what, substeps));
  StepGrid g;
  // The samples (rounded to the nearest whole sample, at least 1), then the steps in all.
  const long n = checked_count(samples, kMaxSteps, fmt::format("{}: samples", what));
  if (n < 1) throw InputError(fmt::format("{}: {:g} samples: need at least 1", what, samples));
  (void)checked_count(static_cast<double>(n) * static_cast<double>(substeps), kMaxSteps, what);
  check_step(sample_s, what);
  g.clock = StepClock::Sampled;
  g.t0_s = t0_s;
  g.sample_s = sample_s;
  g.substeps = substeps;
  g.dt_s = sample_s / static_cast<double>(substeps);
  g.steps = n * substeps;
  return g;
}

StepGrid StepGrid::quasi_static(double increments, std::string_view what) {
  StepGrid g;
  g.clock = StepClock::QuasiStatic;
  g.steps = checked_count(increments, kMaxSteps, what);
  return g;
}

}  // namespace gmasim
