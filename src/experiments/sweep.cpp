// gmasim sweep: temperature x current peak-to-peak x frequency (Fig. 12-14), one simulate()
// per point, points in parallel. docs/experiments.md, "Sweep".
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>

#include "experiments/lane_runs.hpp"
#include "experiments/parallel.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {
namespace {

void check_list(const std::vector<double>& v, const char* what, const char* unit) {
  if (v.empty())
    throw InputError(
        fmt::format("empty grid: no {} given (need at least one value in {})", what, unit));
  for (double x : v)
    if (!std::isfinite(x))
      throw InputError(fmt::format("{} = {} {}: not a finite number", what, x, unit));
  if (static_cast<double>(v.size()) > kMaxListValues)
    throw InputError(
        fmt::format("{} {} values: too many (limit {:g})", v.size(), what, kMaxListValues));
}

struct SweepJob {
  double T, pp, f;
};

void check_request(const Model& m, const SweepRequest& r) {
  check_list(r.temperatures_C, "temperature (--temperatures)", "degC");
  check_list(r.currents_pp_A, "current peak-to-peak (--currents)", "A");
  check_list(r.frequencies_Hz, "frequency (--frequencies)", "Hz");
  for (double f : r.frequencies_Hz)
    if (!(f > 0.0))
      throw InputError(fmt::format("frequency (--frequencies) = {} Hz: must be > 0", f));
  for (double pp : r.currents_pp_A)
    if (!(pp >= 0.0))
      throw InputError(fmt::format("current peak-to-peak (--currents) = {} A: must be >= 0", pp));
  if (!(r.periods >= 1.0) || !std::isfinite(r.periods))
    throw InputError(fmt::format("periods (--periods) = {}: must be >= 1", r.periods));
  require_finite(r.reference_temperature_C, "reference temperature (--reference-temperature)",
                 "degC");
  const double runs = static_cast<double>(r.temperatures_C.size() + 1) *
                      static_cast<double>(r.currents_pp_A.size()) *
                      static_cast<double>(r.frequencies_Hz.size());
  if (runs > kMaxGridRuns)
    throw InputError(
        fmt::format("sweep grid of {:.4g} runs: too many (limit {:g})", runs, kMaxGridRuns));
  if (!(r.dt_s >= 0.0) || !std::isfinite(r.dt_s))
    throw InputError(fmt::format("dt = {} s (--dt): must be >= 0 (0: the automatic rule)", r.dt_s));
  if (!std::isfinite(r.current_min_A))
    throw InputError(fmt::format("current minimum (--current-min) = {} A: not a finite number",
                                 r.current_min_A));
  // Every point's settings must be valid (currents, frequency, run length: simulate's
  // validate()) and every temperature must give valid conditions (T < T_c, ...): fail before
  // any run, not in the middle of the grid.
  for (double pp : r.currents_pp_A)
    for (double f : r.frequencies_Hz) {
      SimulationSettings s;
      s.waveform = biased_sine(pp, f, r.current_min_A);
      s.periods = r.periods;
      s.dt_s = r.dt_s;
      validate(s);
    }
  for (double T : r.temperatures_C) (void)make_conditions(m, T, r.freeze);
  (void)make_conditions(m, r.reference_temperature_C, r.freeze);
}

// Relative changes of the grid's points (slots[0, grid)) against the reference run at equal
// current and frequency.
void add_changes(const SweepRequest& r, bool ref_in_grid, std::size_t grid,
                 std::vector<SweepPoint>& slots) {
  const std::size_t per_T = r.currents_pp_A.size() * r.frequencies_Hz.size();
  auto reference = [&](std::size_t cf) -> const SweepPoint& {
    if (!ref_in_grid) return slots[grid + cf];
    for (std::size_t ti = 0; ti < r.temperatures_C.size(); ++ti)
      if (r.temperatures_C[ti] == r.reference_temperature_C) return slots[ti * per_T + cf];
    return slots[cf];  // unreachable
  };
  const double nan = std::nan("");
  for (std::size_t i = 0; i < grid; ++i) {
    SweepPoint& p = slots[i];
    const SweepPoint& ref = reference(i % per_T);
    if (p.diverged || ref.diverged) {
      p.stroke_change_pct = p.hysteresis_change_pct = p.B_pp_change_pct = nan;
      continue;
    }
    p.stroke_change_pct = detail::change_pct(ref.metrics.stroke_um, p.metrics.stroke_um);
    p.hysteresis_change_pct =
        detail::change_pct(ref.metrics.hysteresis_um, p.metrics.hysteresis_um);
    p.B_pp_change_pct = detail::change_pct(ref.metrics.B_pp_T, p.metrics.B_pp_T);
  }
}

}  // namespace

SweepResult run_sweep(const Model& m, const SweepRequest& r, const ProgressFn& progress) {
  check_request(m, r);
  fields::check_request_fields(r);  // the table's rules (gmasim/experiments/experiment_fields.hpp)
  // The work list: the grid, then the reference temperature if it is not in the grid.
  std::vector<SweepJob> jobs;
  for (double T : r.temperatures_C)
    for (double pp : r.currents_pp_A)
      for (double f : r.frequencies_Hz) jobs.push_back({T, pp, f});
  const std::size_t grid = jobs.size();
  bool ref_in_grid = false;
  for (double T : r.temperatures_C) ref_in_grid = ref_in_grid || T == r.reference_temperature_C;
  if (!ref_in_grid)
    for (double pp : r.currents_pp_A)
      for (double f : r.frequencies_Hz) jobs.push_back({r.reference_temperature_C, pp, f});

  SweepResult res;
  res.threads = resolve_thread_count(r.threads, jobs.size());
  res.simulations = static_cast<long>(jobs.size());
  std::vector<SweepPoint> slots(jobs.size());
  std::vector<SimulationSettings> settings(jobs.size());
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const SweepJob& j = jobs[i];
    SimulationSettings& s = settings[i];
    s.temperature_C = j.T;
    s.waveform = biased_sine(j.pp, j.f, r.current_min_A);
    s.periods = r.periods;
    s.dt_s = r.dt_s;
    s.freeze = r.freeze;
  }
  auto store = [&](std::size_t i, const Result& run) {
    SweepPoint& p = slots[i];
    p.temperature_C = jobs[i].T;
    p.current_pp_A = jobs[i].pp;
    p.frequency_Hz = jobs[i].f;
    p.diverged = run.diverged;
    p.error = run.error;
    if (run.has_metrics) p.metrics = run.metrics;
  };
  const auto wall0 = std::chrono::steady_clock::now();
  // In SIMD lanes, one block of points per thread (lane_runs.hpp); the sweep keeps only the
  // metrics.
  detail::simulate_settings(m, settings, res.threads, r.lanes, true, store, progress);
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  add_changes(r, ref_in_grid, grid, slots);
  res.points.assign(slots.begin(), slots.begin() + static_cast<long>(grid));
  res.reference_points.assign(slots.begin() + static_cast<long>(grid), slots.end());
  return res;
}

}  // namespace gmasim
