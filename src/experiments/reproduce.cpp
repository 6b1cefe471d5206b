// The whole study of the paper, and the claims table of READING-NOTES (the claims are data:
// data/claims.toml; their extractors are src/experiments/claims.cpp).
#include "gmasim/experiments/reproduce.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "experiments/claim_plan.hpp"
#include "experiments/lane_runs.hpp"
#include "gmasim/errors.hpp"

namespace gmasim {

double Claim::rel_diff() const {
  if (!applicable || !std::isfinite(paper) || !std::isfinite(ours) || paper == 0.0)
    return std::numeric_limits<double>::quiet_NaN();
  return (ours - paper) / std::fabs(paper);
}

TimeSeries hysteresis_loops(const Model& m, int threads, bool lanes) {
  TimeSeries loops;
  loops.names = {"temperature_C", "current_A", "y_um", "B_T"};
  loops.columns.assign(4, {});
  std::vector<SimulationSettings> runs;
  for (double T : {20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 100.0, 150.0}) {
    SimulationSettings s;
    s.temperature_C = T;
    s.waveform = biased_sine(8.0, 10.0);
    s.periods = 2;
    runs.push_back(s);
  }
  std::vector<Result> results(runs.size());
  detail::simulate_settings(m, runs, resolve_thread_count(threads, runs.size()), lanes, false,
                            [&](std::size_t i, Result&& res) { results[i] = std::move(res); });
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const Result& res = results[i];
    if (res.diverged || !res.has_metrics) continue;
    const auto& t = res.series.column("t_s");
    const auto& I = res.series.column("current_A");
    const auto& y = res.series.column("y_um");
    const auto& B = res.series.column("B_T");
    for (std::size_t k = 0; k < t.size(); k += 20) {
      if (t[k] < res.metrics.window_start_s - 1e-12) continue;
      loops.columns[0].push_back(runs[i].temperature_C);
      loops.columns[1].push_back(I[k]);
      loops.columns[2].push_back(y[k]);
      loops.columns[3].push_back(B[k]);
    }
  }
  return loops;
}

ReproduceResult run_reproduce(const Model& m, const ReproduceOptions& o,
                              const ProgressFn& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  ReproduceResult r;
  r.model_source = m.spec.source;
  auto opt = [&](const char* k) {
    return std::string(option_word(*find_option_def(k), m.options));
  };
  std::string gaps;
  for (const auto& rod : m.rods)
    gaps += fmt::format("{}{:.4g}", gaps.empty() ? "" : " / ", rod.joint_gap_m * 1e6);
  r.model_readings = fmt::format(
      "magnetic state {}; eq. 10: shape law {}, temperature scale {}; eq. 11: M_s {}; stress sign "
      "{}; eddy law {}; joint gaps {} um; sensor mount base {}",
      opt("magnetic_state"), opt("eq10_shape_law"), opt("eq10_temperature_scale"),
      opt("eq11_saturation"), opt("stress_sign"), opt("eddy_law"), gaps,
      m.sensor_mount.enabled ? opt("sensor_mount_base") : std::string("none"));
  std::size_t stage = 0;
  const std::size_t stages = 7;
  auto next = [&]() {
    if (progress) progress(++stage, stages);
  };
  // The study's requests, one definition with the claim planner's (claim_plan.cpp).
  const detail::StudyRequests g = detail::reproduce_requests(o.quick);
  SweepRequest& s10 = r.sweep_10Hz_request;
  s10 = g.sweep_10Hz;
  s10.threads = o.threads;
  s10.lanes = o.lanes;
  r.sweep_10Hz = run_sweep(m, s10);
  next();
  SweepRequest& sd = r.sweep_dynamic_request;
  sd = g.sweep_dynamic;
  sd.threads = o.threads;
  sd.lanes = o.lanes;
  r.sweep_dynamic = run_sweep(m, sd);
  next();
  r.frf_request = g.frf;
  r.frf = run_frf(m, r.frf_request);
  r.frf_large_request = g.frf_large;
  r.frf_large = run_frf(m, r.frf_large_request);
  next();
  TrackRequest& tr = r.track_request;
  tr = g.track;
  tr.threads = o.threads;
  r.track = run_track(m, tr);
  next();
  r.ablate_request = g.ablate;
  r.ablate_request.lanes = o.lanes;
  r.ablate = run_ablate(m, r.ablate_request);
  next();
  ParamsVsTemperatureRequest& pr = r.params_request;
  pr = g.params;
  pr.lanes = o.lanes;
  r.params = run_params_vs_temperature(m, pr);
  next();
  r.thermal = thermal_expansion_coefficient(m);
  r.loops = hysteresis_loops(m, o.threads, o.lanes);
  r.claims = score_claims(r, o.claims ? *o.claims : builtin_claims());
  mark_fitted(r.claims, m.spec);
  next();
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

Report claims_report(const std::vector<Claim>& claims) {
  Report rep;
  rep.experiment = "claims";
  Table t;
  t.name = "claims";
  t.columns = {"id",
               "claim",
               "source",
               "kind",
               "paper",
               "ours",
               "unit",
               "rel_diff",
               "tolerance",
               "result",
               "pass",
               "fitted",
               "temperature_C",
               "reference_temperature_C",
               "current_pp_A",
               "frequency_Hz",
               "amplitude_um",
               "note"};
  for (const auto& c : claims) {
    const ClaimCondition& k = c.condition;
    t.rows.push_back({c.id, c.claim, c.source, c.kind, c.paper, c.ours, c.unit, c.rel_diff(),
                      c.tolerance, std::string(!c.applicable ? "n/a" : (c.pass ? "pass" : "fail")),
                      c.pass, c.fitted, k.temperature_C, k.reference_temperature_C, k.current_pp_A,
                      k.frequency_Hz, k.amplitude_um, c.note});
  }
  rep.tables.push_back(std::move(t));
  return rep;
}

ClaimCount count_claims(const std::vector<Claim>& claims) {
  ClaimCount n;
  for (const auto& c : claims) {
    n.applicable += c.applicable;
    n.pass += c.pass;
    if (!c.applicable) continue;
    (c.fitted ? n.fitted : n.predicted) += 1;
    (c.fitted ? n.fitted_pass : n.predicted_pass) += c.pass;
  }
  return n;
}

std::string fitted_predicted_line(const ClaimCount& n) {
  return fmt::format("claims: {} of {} fitted pass; {} of {} predicted pass", n.fitted_pass,
                     n.fitted, n.predicted_pass, n.predicted);
}

void mark_fitted(std::vector<Claim>& claims, const ModelSpec& spec) {
  for (const auto& id : spec.fitted_claims) {
    const auto it =
        std::find_if(claims.begin(), claims.end(), [&](const Claim& c) { return c.id == id; });
    if (it == claims.end())
      throw InputError(
          fmt::format("{}:{}: calibration.fitted_claims: '{}' is not a claim of the claims scored",
                      spec.source, spec.line_of("calibration.fitted_claims"), id));
    it->fitted = true;
  }
}

namespace {

std::string md_number(double v) {
  return std::isfinite(v) ? fmt::format("{:.4g}", v) : std::string("-");
}

// A markdown table cell: '|' escaped.
std::string md_cell(std::string s) {
  for (std::size_t p = s.find('|'); p != std::string::npos; p = s.find('|', p + 2))
    s.replace(p, 1, "\\|");
  return s;
}

}  // namespace

std::string claims_markdown(const std::vector<Claim>& claims) {
  std::string md =
      "| # | claim | source | paper | ours | unit | rel. diff | tolerance | fitted / predicted | "
      "result | note |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|\n";
  int n = 0;
  for (const auto& c : claims) {
    const double rd = c.rel_diff();
    md +=
        fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", ++n,
                    md_cell(c.claim), md_cell(c.source), md_number(c.paper), md_number(c.ours),
                    c.unit, std::isfinite(rd) ? fmt::format("{:+.1f} %", 100 * rd) : "-",
                    md_cell(c.tolerance), !c.applicable ? "-" : (c.fitted ? "fitted" : "predicted"),
                    !c.applicable ? "n/a" : (c.pass ? "PASS" : "FAIL"), md_cell(c.note));
  }
  const ClaimCount k = count_claims(claims);
  md += fmt::format(
      "\n**{} of {} applicable claims pass** ({} claims, {} not applicable): **{}**. A fitted "
      "claim is a target of the model's calibration (or set by a chosen constant); only the "
      "predicted ones test the model.\n",
      k.pass, k.applicable, n, n - k.applicable, fitted_predicted_line(k));
  return md;
}

std::string comparison_markdown(const std::vector<ComparedModel>& models) {
  if (models.empty()) return "";
  std::string md =
      "\n## Readings compared\n\nThe same claims scored on each calibrated reading "
      "(calibration/calibrate.sh; docs/calibration.md). A cell is our value and PASS/FAIL.\n\n";
  md += "| claim | paper |";
  for (const auto& m : models) md += " " + m.name + " |";
  md += "\n|---|---|";
  for (std::size_t i = 0; i < models.size(); ++i) md += "---|";
  md += "\n";
  for (std::size_t k = 0; k < models.front().claims.size(); ++k) {
    const Claim& c0 = models.front().claims[k];
    if (!c0.applicable) continue;
    md += fmt::format("| {} | {} |", md_cell(c0.claim), md_number(c0.paper));
    for (const auto& m : models)
      md +=
          fmt::format(" {} {} |", md_number(m.claims[k].ours), m.claims[k].pass ? "PASS" : "FAIL");
    md += "\n";
  }
  // Readings are chosen by the claims they predict (issue 37): each count on its own row.
  std::vector<ClaimCount> counts;
  for (const auto& m : models) counts.push_back(count_claims(m.claims));
  md += "| **claims met** | |";
  for (const auto& n : counts) md += fmt::format(" **{} of {}** |", n.pass, n.applicable);
  md += "\n| **predicted claims met** | |";
  for (const auto& n : counts) md += fmt::format(" **{} of {}** |", n.predicted_pass, n.predicted);
  md += "\n| fitted claims met | |";
  for (const auto& n : counts) md += fmt::format(" {} of {} |", n.fitted_pass, n.fitted);
  md += "\n\nReadings: ";
  for (const auto& m : models) md += fmt::format("`{}` = {}; ", m.name, m.readings);
  md += "\n";
  return md;
}

}  // namespace gmasim
