// gmasim ablate (Fig. 20): each temperature law frozen at T_ref (20 degC), one at a time;
// the deviation of the frozen model from the full model at the operating temperature.
// docs/experiments.md, "Ablation".
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "experiments/lane_runs.hpp"
#include "experiments/parallel.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {

std::vector<AblationLaw> ablation_laws() {
  std::vector<AblationLaw> laws;
  Freeze all;
  for (const auto& sw : kFreezeSwitches) {
    AblationLaw l;
    l.name = sw.name;
    l.description = sw.description;
    l.freeze.*(sw.flag) = true;
    all.*(sw.flag) = true;
    laws.push_back(l);
  }
  laws.push_back(
      {"all", "every law above at once: the 20 degC model run at the operating temperature", all});
  return laws;
}

namespace {

void check_request(const Model& m, const AblateRequest& r) {
  if (r.frequencies_Hz.empty()) throw InputError("ablate: no frequency given");
  for (double f : r.frequencies_Hz)
    if (!(f > 0.0) || !std::isfinite(f))
      throw InputError(fmt::format("frequency (--frequencies) = {} Hz: must be > 0", f));
  // > 0: the errors are given in % of the stroke, which a zero drive does not have (inf, nan)
  if (!(r.current_pp_A > 0.0) || !std::isfinite(r.current_pp_A))
    throw InputError(
        fmt::format("current peak-to-peak (--current-pp) = {} A: must be > 0", r.current_pp_A));
  if (!(r.periods >= 1.0) || !std::isfinite(r.periods))
    throw InputError(fmt::format("periods {}: must be >= 1", r.periods));
  (void)make_conditions(m, r.temperature_C);  // T < T_c
  if (static_cast<double>(r.frequencies_Hz.size()) > kMaxListValues)
    throw InputError(fmt::format("ablate: {} frequencies: too many (limit {:g})",
                                 r.frequencies_Hz.size(), kMaxListValues));
  for (double f : r.frequencies_Hz) {  // every run's settings, before any run
    SimulationSettings s;
    s.waveform = biased_sine(r.current_pp_A, f, r.current_min_A);
    s.periods = r.periods;
    validate(s);
  }
}

struct AblationRun {  // only what the comparison needs (a full Result holds every column)
  std::vector<double> t, y;
  Metrics metrics;
  bool diverged = false;
  std::string error;
};

// The deviation of a frozen run from the full one over the full run's metrics window.
AblationRow compare(const AblationRun& full, const AblationRun& fr, const std::string& law,
                    double f) {
  AblationRow row;
  row.law = law;
  row.frequency_Hz = f;
  row.diverged = fr.diverged;
  row.error = fr.error;
  const double nan = std::nan("");
  if (fr.diverged || fr.y.size() != full.y.size()) {
    row.error_rms_um = row.error_peak_um = row.error_pct_of_stroke = nan;
    row.stroke_um = row.hysteresis_um = row.stroke_change_pct = row.hysteresis_change_pct = nan;
    return row;
  }
  const auto& t = full.t;
  const double eps = 1e-9 * (full.metrics.window_end_s - full.metrics.window_start_s);
  const auto b = static_cast<std::size_t>(
      std::lower_bound(t.begin(), t.end(), full.metrics.window_start_s - eps) - t.begin());
  const auto e = static_cast<std::size_t>(
      std::lower_bound(t.begin(), t.end(), full.metrics.window_end_s - eps) - t.begin());
  // Same waveform, same dt: the two runs share the time grid sample for sample.
  std::vector<double> d(fr.y.size());
  for (std::size_t k = b; k < e; ++k) d[k] = fr.y[k] - full.y[k];
  const RmsPeak rp = rms_and_peak(d, b, e);
  row.error_rms_um = rp.rms;
  row.error_peak_um = rp.peak;
  row.error_pct_of_stroke = rp.rms / full.metrics.stroke_um * 100.0;
  row.stroke_um = fr.metrics.stroke_um;
  row.hysteresis_um = fr.metrics.hysteresis_um;
  row.stroke_change_pct = detail::change_pct(full.metrics.stroke_um, fr.metrics.stroke_um);
  row.hysteresis_change_pct =
      detail::change_pct(full.metrics.hysteresis_um, fr.metrics.hysteresis_um);
  return row;
}

}  // namespace

AblateResult run_ablate(const Model& m, const AblateRequest& r) {
  check_request(m, r);
  fields::check_request_fields(r);  // the table's rules (gmasim/experiments/experiment_fields.hpp)
  const auto laws = ablation_laws();
  const std::size_t per_f = laws.size() + 1;  // the full model, then each law
  const std::size_t n = r.frequencies_Hz.size() * per_f;
  std::vector<SimulationSettings> settings(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t fi = i / per_f, li = i % per_f;
    SimulationSettings& s = settings[i];
    s.temperature_C = r.temperature_C;
    s.waveform = biased_sine(r.current_pp_A, r.frequencies_Hz[fi], r.current_min_A);
    s.periods = r.periods;
    if (li > 0) s.freeze = laws[li - 1].freeze;
  }
  std::vector<AblationRun> runs(n);
  detail::simulate_settings(m, settings, resolve_thread_count(r.threads, n), r.lanes, false,
                            [&](std::size_t i, Result&& out) {
                              AblationRun& run = runs[i];
                              run.diverged = out.diverged;
                              run.error = out.error;
                              run.metrics = out.metrics;
                              run.t = out.series.column("t_s");
                              run.y = out.series.column("y_um");
                            });

  AblateResult res;
  for (std::size_t fi = 0; fi < r.frequencies_Hz.size(); ++fi) {
    const AblationRun& full = runs[fi * per_f];
    if (full.diverged)  // the run's own diagnosis (time, rod, quantity), after the point
      throw DivergenceError(fmt::format("ablate: the full model at {:g} degC, {:g} Hz diverged: {}",
                                        r.temperature_C, r.frequencies_Hz[fi], full.error));
    res.full.push_back(full.metrics);
    for (std::size_t li = 0; li < laws.size(); ++li)
      res.rows.push_back(
          compare(full, runs[fi * per_f + li + 1], laws[li].name, r.frequencies_Hz[fi]));
  }
  return res;
}

}  // namespace gmasim
