// Reports of the experiments: one table per result (one row per point, column names with
// units). Written as CSV and JSON by src/io/report_text.cpp.
#include <cmath>

#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "request_meta.hpp"

namespace gmasim {
namespace {

std::string status(bool diverged) { return diverged ? "diverged" : "ok"; }

Report base(const std::string& experiment, const Model& m) {
  Report r;
  r.experiment = experiment;
  r.meta.emplace_back("model", m.spec.source);
  return r;
}

}  // namespace

// ---------------------------------------------------------------------------------------
Report sweep_report(const Model& m, const SweepRequest& req, const SweepResult& res) {
  Report r = base("sweep", m);
  fields::add_request_meta(r, req);
  r.meta.emplace_back("threads", res.threads);
  r.meta.emplace_back("simulations", static_cast<double>(res.simulations));
  r.meta.emplace_back("wall_time_s", res.wall_time_s);
  r.meta.emplace_back("metrics_window", "the last whole period");
  auto table = [&](const std::string& name, const std::vector<SweepPoint>& pts) {
    Table t;
    t.name = name;
    t.columns = {"temperature_C",         "current_pp_A",    "frequency_Hz", "stroke_um",
                 "hysteresis_um",         "B_pp_T",          "y_mean_um",    "stroke_change_pct",
                 "hysteresis_change_pct", "B_pp_change_pct", "status",       "error"};
    const double nan = std::nan("");
    for (const auto& p : pts) {
      const bool ok = !p.diverged;
      t.rows.push_back({p.temperature_C, p.current_pp_A, p.frequency_Hz,
                        ok ? p.metrics.stroke_um : nan, ok ? p.metrics.hysteresis_um : nan,
                        ok ? p.metrics.B_pp_T : nan, ok ? p.metrics.y_mean_um : nan,
                        p.stroke_change_pct, p.hysteresis_change_pct, p.B_pp_change_pct,
                        status(p.diverged), p.error});
    }
    return t;
  };
  r.tables.push_back(table("points", res.points));
  if (!res.reference_points.empty())
    r.tables.push_back(table("reference_points", res.reference_points));
  return r;
}

Report frf_report(const Model& m, const FrfRequest& req, const FrfResult& res) {
  Report r = base("frf", m);
  fields::add_request_meta(r, req);
  r.meta.emplace_back("paper_first_resonance_Hz", res.paper_first_resonance_Hz);
  r.meta.emplace_back("paper_bandwidth_Hz_at_least", res.paper_bandwidth_Hz);
  if (!res.curves.empty()) r.meta.emplace_back("wall_time_s", res.curves.front().wall_time_s);
  const double nan = std::nan("");
  Table pts{"response",
            {"temperature_C", "frequency_Hz", "stepped_mag_um_per_A", "stepped_phase_deg",
             "linear_mag_um_per_A", "linear_phase_deg", "mismatch_pct"},
            {}};
  Table sum{"summary",
            {"temperature_C", "first_resonance_Hz", "linear_peak_extended_Hz",
             "linear_peak_search_max_Hz", "bandwidth_3dB_Hz", "stepped_first_resonance_Hz",
             "stepped_bandwidth_3dB_Hz", "static_gain_um_per_A", "y_bias_um", "max_mismatch_pct",
             "paper_first_resonance_Hz", "paper_bandwidth_Hz_at_least", "small_signal_limit_A",
             "large_signal", "markers_from", "reference_gain_um_per_A"},
            {}};
  Table modes{"modes",
              {"temperature_C", "mode", "frequency_Hz", "damping_ratio", "damped_frequency_Hz"},
              {}};
  Table tau{"eddy", {"temperature_C", "rod", "tau_eddy_ms"}, {}};
  for (const auto& c : res.curves) {
    for (std::size_t k = 0; k < c.f_Hz.size(); ++k) {
      const bool s = k < c.stepped_mag_um_per_A.size(), l = k < c.linear_mag_um_per_A.size();
      double mis = nan;
      if (s && l) {
        const auto Ys =
            std::polar(c.stepped_mag_um_per_A[k], c.stepped_phase_deg[k] * physics::kPi / 180);
        const auto Yl =
            std::polar(c.linear_mag_um_per_A[k], c.linear_phase_deg[k] * physics::kPi / 180);
        mis = std::abs(Ys - Yl) / std::abs(Yl) * 100.0;
      }
      pts.rows.push_back({c.temperature_C, c.f_Hz[k], s ? c.stepped_mag_um_per_A[k] : nan,
                          s ? c.stepped_phase_deg[k] : nan, l ? c.linear_mag_um_per_A[k] : nan,
                          l ? c.linear_phase_deg[k] : nan, mis});
    }
    sum.rows.push_back({c.temperature_C, c.first_resonance_Hz, c.linear_peak_extended_Hz,
                        c.linear_peak_search_max_Hz, c.bandwidth_3dB_Hz,
                        c.stepped_first_resonance_Hz, c.stepped_bandwidth_3dB_Hz,
                        c.static_gain_um_per_A, c.y_bias_um, c.max_mismatch_pct,
                        res.paper_first_resonance_Hz, res.paper_bandwidth_Hz,
                        std::isfinite(c.small_signal_limit_A) ? c.small_signal_limit_A : nan,
                        c.large_signal, c.markers_from, c.reference_gain_um_per_A});
    for (std::size_t k = 0; k < c.mode_frequencies_Hz.size(); ++k) {
      const double z = c.mode_damping_ratios[k];
      modes.rows.push_back({c.temperature_C, static_cast<int>(k + 1), c.mode_frequencies_Hz[k], z,
                            z < 1 ? c.mode_frequencies_Hz[k] * std::sqrt(1 - z * z) : 0.0});
    }
    for (std::size_t k = 0; k < c.eddy_tau_ms.size() && k < m.rods.size(); ++k)
      tau.rows.push_back({c.temperature_C, m.rods[k].name, c.eddy_tau_ms[k]});
  }
  r.tables = {pts, sum, modes, tau};
  return r;
}

Report track_report(const Model& m, const TrackRequest& req, const TrackResult& res) {
  Report r = base("track", m);
  fields::add_request_meta(r, req);
  fields::insert_meta_after(r, "sample_rate_Hz", "plant_dt_s", res.plant_dt_s);
  r.meta.emplace_back("controller",
                      req.controller ? "user (TrackRequest::controller)" : "PID (gains above)");
  r.meta.emplace_back("error_window", "the last whole period of the reference, every plant step");
  r.meta.emplace_back("threads", res.threads);
  r.meta.emplace_back("wall_time_s", res.wall_time_s);
  Table t{"points",
          {"temperature_C", "amplitude_um", "frequency_Hz", "error_rms_um", "error_peak_um",
           "error_rms_pct_of_amplitude", "error_change_pct", "y_bias_um", "current_min_A",
           "current_max_A", "saturated", "error_alternation", "error_oscillation_Hz", "limit_cycle",
           "status", "error"},
          {}};
  for (const auto& p : res.points)
    t.rows.push_back({p.temperature_C, p.amplitude_um, p.frequency_Hz, p.error_rms_um,
                      p.error_peak_um, p.error_rms_pct, p.error_change_pct, p.y_bias_um,
                      p.current_min_A, p.current_max_A, p.saturated, p.error_alternation,
                      p.error_oscillation_Hz, p.limit_cycle, status(p.diverged), p.error});
  r.tables.push_back(t);
  Table margins{"margins",
                {"temperature_C", "gain_margin_dB", "phase_crossover_Hz", "phase_margin_deg",
                 "gain_crossover_Hz", "closed_loop_pole_radius", "closed_loop_pole_Hz", "stable"},
                {}};
  for (const auto& k : res.margins)
    margins.rows.push_back({k.temperature_C, k.gain_margin_dB, k.phase_crossover_Hz,
                            k.phase_margin_deg, k.gain_crossover_Hz, k.spectral_radius,
                            k.dominant_Hz, k.stable});
  r.tables.push_back(margins);
  return r;
}

Report ablate_report(const Model& m, const AblateRequest& req, const AblateResult& res) {
  Report r = base("ablate", m);
  fields::add_request_meta(r, req);
  r.meta.emplace_back("frozen_at_C", m.T_ref_C);
  r.meta.emplace_back("error_definition",
                      "RMS over the last period of y_frozen(t) - y_full(t) on the same time grid");
  Table t{
      "ablation",
      {"law", "frequency_Hz", "error_rms_um", "error_peak_um", "error_pct_of_stroke", "stroke_um",
       "hysteresis_um", "stroke_change_pct", "hysteresis_change_pct", "status", "error"},
      {}};
  for (const auto& row : res.rows)
    t.rows.push_back({row.law, row.frequency_Hz, row.error_rms_um, row.error_peak_um,
                      row.error_pct_of_stroke, row.stroke_um, row.hysteresis_um,
                      row.stroke_change_pct, row.hysteresis_change_pct, status(row.diverged),
                      row.error});
  Table full{"full_model", {"frequency_Hz", "stroke_um", "hysteresis_um", "B_pp_T"}, {}};
  for (std::size_t k = 0; k < res.full.size() && k < req.frequencies_Hz.size(); ++k)
    full.rows.push_back({req.frequencies_Hz[k], res.full[k].stroke_um, res.full[k].hysteresis_um,
                         res.full[k].B_pp_T});
  Table laws{"laws", {"law", "freezes"}, {}};
  for (const auto& l : ablation_laws()) laws.rows.push_back({l.name, l.description});
  r.tables = {t, full, laws};
  return r;
}

Report params_report(const Model& m, const ParamsVsTemperatureRequest& req,
                     const ParamsVsTemperatureResult& res) {
  Report r = base("params-vs-temperature", m);
  fields::add_request_meta(r, req);
  Table p{"parameters",
          {"temperature_C", "rod", "mu_r_mean", "rho_ohm_m", "M_peak_A_per_m", "MsT_A_per_m",
           "E_G_mean_GPa", "E_t_GPa", "mu_r_change_pct", "rho_change_pct", "M_peak_change_pct",
           "E_G_change_pct", "E_t_change_pct"},
          {}};
  for (const auto& w : res.rows)
    p.rows.push_back({w.temperature_C, w.rod, w.mu_r_mean, w.rho_ohm_m, w.M_peak_A_per_m,
                      w.MsT_A_per_m, w.E_G_mean_GPa, w.E_t_GPa, w.mu_r_change_pct, w.rho_change_pct,
                      w.M_peak_change_pct, w.E_G_change_pct, w.E_t_change_pct});
  Table q{"retention",
          {"current_pp_A", "temperature_C", "stroke_um", "hysteresis_um", "stroke_retention_pct",
           "hysteresis_retention_pct"},
          {}};
  for (const auto& w : res.retention)
    q.rows.push_back({w.current_pp_A, w.temperature_C, w.stroke_um, w.hysteresis_um,
                      w.stroke_retention_pct, w.hysteresis_retention_pct});
  r.tables = {p, q};
  return r;
}

Report thermal_report(const Model& m, const ThermalExpansionResult& res) {
  Report r = base("thermal", m);
  r.meta.emplace_back("um_per_C", res.um_per_C);
  r.meta.emplace_back("paper_model_um_per_C", res.paper_model_um_per_C);
  r.meta.emplace_back("paper_measured_um_per_C", res.paper_measured_um_per_C);
  Table t{"eq21_terms", {"term", "um_per_C"}, {}};
  t.rows.push_back({"magnetostrictive rods (+alpha_G l_G)", res.rod_um_per_C});
  t.rows.push_back({"magnetizers (+alpha_M l_M)", res.magnetizer_um_per_C});
  t.rows.push_back({"output rod (+alpha_s l_s)", res.output_rod_um_per_C});
  t.rows.push_back({"sleeve (-alpha_t l_t)", -res.sleeve_um_per_C});
  t.rows.push_back({"total, eq. (21)", res.um_per_C});
  t.rows.push_back({"paper, model", res.paper_model_um_per_C});
  t.rows.push_back({"paper, measured", res.paper_measured_um_per_C});
  r.tables = {t};
  return r;
}

}  // namespace gmasim
