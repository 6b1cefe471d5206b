// gmasim params-vs-temperature: mu_G, rho_G, M_G, E_G, E_t from 20 to 150 degC (Fig. 19)
// and the stroke retention at high temperature (Fig. 18). docs/experiments.md.
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
namespace {

struct RodStats {
  double mu_r_mean = 0, M_peak = 0, E_mean_GPa = 0;
};

struct PointRun {
  Metrics metrics;
  bool diverged = false;
  std::string error;
  std::vector<RodStats> rods;  // filled for the Fig. 19 operating point only
};

double mean_of(const std::vector<double>& v, std::size_t b, std::size_t e) {
  double s = 0.0;
  for (std::size_t i = b; i < e; ++i) s += v[i];
  return e > b ? s / static_cast<double>(e - b) : 0.0;
}

void check_request(const ParamsVsTemperatureRequest& r) {
  if (r.temperatures_C.empty())
    throw InputError(
        "params-vs-temperature: no temperature given (--temperatures): give at least one");
  if (!(r.frequency_Hz > 0.0) || !std::isfinite(r.frequency_Hz))
    throw InputError(fmt::format("frequency (--frequency) = {} Hz: must be > 0", r.frequency_Hz));
  for (double pp : r.retention_currents_pp_A)
    if (!(pp > 0.0) || !std::isfinite(pp))  // > 0: the retention is a ratio of strokes
      throw InputError(fmt::format(
          "retention current peak-to-peak (--retention-currents) = {} A: must be > 0", pp));
  // > 0: the errors are given in % of the stroke, which a zero drive does not have (inf, nan)
  if (!(r.current_pp_A > 0.0) || !std::isfinite(r.current_pp_A))
    throw InputError(
        fmt::format("current peak-to-peak (--current-pp) = {} A: must be > 0", r.current_pp_A));
  if (!(r.periods >= 1.0)) throw InputError(fmt::format("periods {}: must be >= 1", r.periods));
  if (static_cast<double>(r.temperatures_C.size()) > kMaxListValues ||
      static_cast<double>(r.retention_currents_pp_A.size()) > kMaxListValues)
    throw InputError(
        fmt::format("params-vs-temperature: more than {:g} values in a list", kMaxListValues));
  for (double pp : r.retention_currents_pp_A) {  // every run's settings, before any run
    SimulationSettings s;
    s.waveform = biased_sine(pp, r.frequency_Hz, r.current_min_A);
    s.periods = r.periods;
    s.dt_s = r.dt_s;
    validate(s);
  }
  {
    SimulationSettings s;
    s.waveform = biased_sine(r.current_pp_A, r.frequency_Hz, r.current_min_A);
    s.periods = r.periods;
    s.dt_s = r.dt_s;
    validate(s);
  }
}

// One run's settings.
SimulationSettings point_settings(const ParamsVsTemperatureRequest& r, double T, double pp) {
  SimulationSettings s;
  s.temperature_C = T;
  s.waveform = biased_sine(pp, r.frequency_Hz, r.current_min_A);
  s.periods = r.periods;
  s.dt_s = r.dt_s;
  return s;
}

// One run's numbers: the metrics; at the Fig. 19 operating point (with_rods) also each rod's
// mean mu_r, mean E_G and peak M over the metrics window.
PointRun point_run(const Model& m, const ParamsVsTemperatureRequest& r, const Result& out,
                   bool with_rods) {
  PointRun run;
  run.diverged = out.diverged;
  run.error = out.error;
  run.metrics = out.metrics;
  if (!with_rods || out.diverged) return run;
  const auto& t = out.series.column("t_s");
  const double eps = 1e-9 / r.frequency_Hz;
  const auto b = static_cast<std::size_t>(
      std::lower_bound(t.begin(), t.end(), out.metrics.window_start_s - eps) - t.begin());
  const auto e = static_cast<std::size_t>(
      std::lower_bound(t.begin(), t.end(), out.metrics.window_end_s - eps) - t.begin());
  for (const auto& rod : m.rods) {
    RodStats st;
    st.mu_r_mean = mean_of(out.series.column(rod.name + "_mu_r"), b, e);
    st.E_mean_GPa = mean_of(out.series.column(rod.name + "_E_GPa"), b, e);
    st.M_peak = rms_and_peak(out.series.column(rod.name + "_M_A_per_m"), b, e).peak;
    run.rods.push_back(st);
  }
  return run;
}

// The Fig. 19 rows: per temperature and rod the laws and the run's means, with their changes
// against the first temperature.
void add_law_rows(const Model& m, const ParamsVsTemperatureRequest& r,
                  const std::vector<Conditions>& conds, const std::vector<PointRun>& runs,
                  std::size_t nc, std::size_t op, ParamsVsTemperatureResult& res) {
  const double nan = std::nan("");
  for (std::size_t ti = 0; ti < r.temperatures_C.size(); ++ti) {
    const PointRun& run = runs[ti * nc + op];
    const Conditions& c = conds[ti];
    for (std::size_t k = 0; k < m.rods.size(); ++k) {
      ParamsVsTemperatureRow row;
      row.temperature_C = r.temperatures_C[ti];
      row.rod = m.rods[k].name;
      row.rho_ohm_m = c.rods[k].rho_ohm_m;
      row.MsT_A_per_m = c.rods[k].MsT_mag;
      row.E_t_GPa = c.Et_Pa * 1e-9;
      if (run.diverged) {
        row.mu_r_mean = row.M_peak_A_per_m = row.E_G_mean_GPa = nan;
      } else {
        row.mu_r_mean = run.rods[k].mu_r_mean;
        row.M_peak_A_per_m = run.rods[k].M_peak;
        row.E_G_mean_GPa = run.rods[k].E_mean_GPa;
      }
      res.rows.push_back(row);
    }
  }
  const std::size_t nr = m.rods.size();
  for (std::size_t i = 0; i < res.rows.size(); ++i) {
    const auto& first = res.rows[i % nr];
    auto& row = res.rows[i];
    row.mu_r_change_pct = detail::change_pct(first.mu_r_mean, row.mu_r_mean);
    row.rho_change_pct = detail::change_pct(first.rho_ohm_m, row.rho_ohm_m);
    row.M_peak_change_pct = detail::change_pct(first.M_peak_A_per_m, row.M_peak_A_per_m);
    row.E_G_change_pct = detail::change_pct(first.E_G_mean_GPa, row.E_G_mean_GPa);
    row.E_t_change_pct = detail::change_pct(first.E_t_GPa, row.E_t_GPa);
  }
}

}  // namespace

ParamsVsTemperatureResult run_params_vs_temperature(const Model& m,
                                                    const ParamsVsTemperatureRequest& r) {
  check_request(r);
  fields::check_request_fields(r);  // the table's rules (gmasim/experiments/experiment_fields.hpp)
  std::vector<Conditions> conds;
  for (double T : r.temperatures_C) conds.push_back(make_conditions(m, T));

  // Currents per temperature: the retention currents, plus the Fig. 19 point if it is not
  // one of them.
  std::vector<double> currents = r.retention_currents_pp_A;
  std::size_t op = currents.size();
  for (std::size_t k = 0; k < currents.size(); ++k)
    if (currents[k] == r.current_pp_A) op = k;
  if (op == currents.size()) currents.push_back(r.current_pp_A);
  const std::size_t nc = currents.size(), n = r.temperatures_C.size() * nc;

  std::vector<SimulationSettings> settings;
  for (std::size_t i = 0; i < n; ++i)
    settings.push_back(point_settings(r, r.temperatures_C[i / nc], currents[i % nc]));
  std::vector<PointRun> runs(n);
  detail::simulate_settings(
      m, settings, resolve_thread_count(r.threads, n), r.lanes, false,
      [&](std::size_t i, Result&& out) { runs[i] = point_run(m, r, out, i % nc == op); });
  // A diverged run ends the command with its diagnosis (as sweep, frf and ablate do), instead
  // of tables of NaN with exit 0.
  for (std::size_t i = 0; i < n; ++i)
    if (runs[i].diverged)
      throw DivergenceError(fmt::format(
          "params-vs-temperature: the run at {:g} degC, {:g} A peak-to-peak, {:g} Hz diverged: {}",
          r.temperatures_C[i / nc], currents[i % nc], r.frequency_Hz, runs[i].error));

  ParamsVsTemperatureResult res;
  add_law_rows(m, r, conds, runs, nc, op, res);
  const double nan = std::nan("");
  for (std::size_t ci = 0; ci < r.retention_currents_pp_A.size(); ++ci) {
    const PointRun& first = runs[ci];
    for (std::size_t ti = 0; ti < r.temperatures_C.size(); ++ti) {
      const PointRun& run = runs[ti * nc + ci];
      RetentionRow row;
      row.current_pp_A = currents[ci];
      row.temperature_C = r.temperatures_C[ti];
      if (run.diverged || first.diverged) {
        row.stroke_um = row.hysteresis_um = row.stroke_retention_pct =
            row.hysteresis_retention_pct = nan;
      } else {
        row.stroke_um = run.metrics.stroke_um;
        row.hysteresis_um = run.metrics.hysteresis_um;
        row.stroke_retention_pct = run.metrics.stroke_um / first.metrics.stroke_um * 100.0;
        row.hysteresis_retention_pct =
            run.metrics.hysteresis_um / first.metrics.hysteresis_um * 100.0;
      }
      res.retention.push_back(row);
    }
  }
  return res;
}

}  // namespace gmasim
