// The parts of the reproduce study that some claims need, and run_claims (gmasim/
// sensitivity.hpp). Each extractor (src/experiments/claims.cpp) reads one part of the study at
// the claim's condition; every point of a part is an independent run (a sweep point and its
// reference run, an FRF curve at one temperature, a tracking run, ...), so the parts at only
// the claims' conditions give the same numbers as the whole study.
#include "experiments/claim_plan.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string_view>

#include "common/numbers.hpp"
#include "experiments/parallel.hpp"
#include "gmasim/errors.hpp"

namespace gmasim::detail {
namespace {

bool same(double a, double b) { return std::fabs(a - b) < 1e-9; }  // as the extractors compare

bool has(const std::vector<double>& v, double x) {
  return std::any_of(v.begin(), v.end(), [&](double y) { return same(x, y); });
}

// The values of `grid` that are in `wanted`, in the grid's order.
std::vector<double> keep(const std::vector<double>& grid, const std::vector<double>& wanted) {
  std::vector<double> out;
  for (double x : grid)
    if (has(wanted, x)) out.push_back(x);
  return out;
}

// The part of the study each extractor kind reads (claims.cpp, kinds()).
enum class Part {
  Sweep,
  SweepFamily,
  Frf,
  FrfLarge,
  Params,
  Track,
  Ablate,
  Thermal,
  None,
  Unknown
};

Part part_of(std::string_view kind) {
  static constexpr std::string_view kSweep[] = {"stroke_drop_pct", "hysteresis_drop_pct",
                                                "flux_drop_pct",   "stroke_um",
                                                "hysteresis_um",   "B_pp_T"};
  for (auto k : kSweep)
    if (k == kind) return Part::Sweep;
  if (kind == "stroke_drop_slope_pct_per_A" || kind == "hysteresis_drop_slope_pct_per_A" ||
      kind == "flux_drop_slope_pct_per_A")
    return Part::SweepFamily;
  if (kind == "first_resonance_Hz" || kind == "resonance_shift_pct" || kind == "bandwidth_Hz")
    return Part::Frf;
  if (kind == "resonance_amplitude_change_pct") return Part::FrfLarge;
  if (kind == "stroke_retention_pct" || kind == "EG_rise_pct" || kind == "param_change_pct")
    return Part::Params;
  if (kind == "track_error_growth_pct") return Part::Track;
  if (kind == "ablation_error_um") return Part::Ablate;
  if (kind == "thermal_expansion_um_per_C") return Part::Thermal;
  if (kind == "paper_measurements") return Part::None;
  return Part::Unknown;
}

// What the claims need, condition by condition.
struct Needs {
  std::vector<std::array<double, 3>> sweep_10Hz, sweep_dynamic;  // (T, I, f)
  std::vector<double> frf_T, frf_large_T, track_T, track_A, ablate_f, params_T, retention_I;
  bool params = false, full = false;
};

void need_sweep(const StudyRequests& g, const ClaimCondition& c, Needs& n) {
  auto in = [&](const SweepRequest& s) {
    return has(s.temperatures_C, c.temperature_C) && has(s.currents_pp_A, c.current_pp_A) &&
           has(s.frequencies_Hz, c.frequency_Hz);
  };
  if (in(g.sweep_10Hz))
    n.sweep_10Hz.push_back({c.temperature_C, c.current_pp_A, c.frequency_Hz});
  else if (in(g.sweep_dynamic))
    n.sweep_dynamic.push_back({c.temperature_C, c.current_pp_A, c.frequency_Hz});
}

// Every current of the grid at the claim's (T, f): the family a slope claim reads.
void need_family(const StudyRequests& g, const ClaimCondition& c, Needs& n) {
  for (const SweepRequest* s : {&g.sweep_10Hz, &g.sweep_dynamic}) {
    if (!has(s->frequencies_Hz, c.frequency_Hz) || !has(s->temperatures_C, c.temperature_C))
      continue;
    for (double I : s->currents_pp_A) {
      ClaimCondition one = c;
      one.current_pp_A = I;
      need_sweep(g, one, n);
    }
    return;
  }
}

void need(const StudyRequests& g, const ClaimSpec& s, Needs& n) {
  if (s.tolerance.kind == ToleranceKind::NotApplicable) return;  // never extracted
  const ClaimCondition& c = s.condition;
  switch (part_of(s.kind)) {
    case Part::Sweep:
      need_sweep(g, c, n);
      break;
    case Part::SweepFamily:
      need_family(g, c, n);
      break;
    case Part::Frf:
      n.frf_T.push_back(c.temperature_C);
      if (!std::isnan(c.reference_temperature_C)) n.frf_T.push_back(c.reference_temperature_C);
      break;
    case Part::FrfLarge:
      n.frf_large_T.push_back(c.temperature_C);
      n.frf_large_T.push_back(c.reference_temperature_C);
      break;
    case Part::Params:
      n.params = true;
      n.params_T.push_back(c.temperature_C);
      if (s.kind == "stroke_retention_pct") n.retention_I.push_back(c.current_pp_A);
      break;
    case Part::Track:
      n.track_T.push_back(c.temperature_C);
      n.track_A.push_back(c.amplitude_um);
      break;
    case Part::Ablate:
      n.ablate_f.push_back(c.frequency_Hz);
      break;
    case Part::Thermal:
    case Part::None:
      break;
    case Part::Unknown:
      n.full = true;
      break;
  }
}

// One sweep request per (current, frequency) of `points`, each with the grid's settings and
// the needed temperatures in the grid's order.
std::vector<SweepRequest> split_sweep(const SweepRequest& grid,
                                      const std::vector<std::array<double, 3>>& points) {
  std::vector<SweepRequest> out;
  for (double I : grid.currents_pp_A)
    for (double f : grid.frequencies_Hz) {
      std::vector<double> Ts;
      for (const auto& p : points)
        if (same(p[1], I) && same(p[2], f)) Ts.push_back(p[0]);
      if (Ts.empty()) continue;
      SweepRequest r = grid;
      r.temperatures_C = keep(grid.temperatures_C, Ts);
      r.currents_pp_A = {I};
      r.frequencies_Hz = {f};
      r.threads = 1;
      out.push_back(std::move(r));
    }
  return out;
}

// The filtered requests of the FRF, tracking, ablation and 20-150 degC parts.
void plan_parts(const Needs& n, ClaimPlan& p) {
  const StudyRequests& g = p.grid;
  p.frf_request = g.frf;
  p.frf_request.temperatures_C = keep(g.frf.temperatures_C, n.frf_T);
  p.frf_request.stepped_sine = false;  // every FRF claim reads the small-signal curve
  p.frf_request.threads = 1;
  p.frf = !p.frf_request.temperatures_C.empty();
  p.frf_large_request = g.frf_large;
  p.frf_large_request.temperatures_C = keep(g.frf_large.temperatures_C, n.frf_large_T);
  p.frf_large_request.threads = 1;
  p.frf_large = !p.frf_large_request.temperatures_C.empty();

  // Tracking: the first temperature (the reference of the growth) and the claims'; the
  // frequencies whole (they set the plant step). With sensor noise the per-point seeds follow
  // the grid's order, so then the whole grid runs.
  p.track_request = g.track;
  p.track_request.threads = 1;
  if (g.track.sensor_noise_um == 0.0) {
    std::vector<double> tT = n.track_T;
    if (!g.track.temperatures_C.empty()) tT.push_back(g.track.temperatures_C.front());
    p.track_request.temperatures_C = keep(g.track.temperatures_C, tT);
    p.track_request.amplitudes_um = keep(g.track.amplitudes_um, n.track_A);
  }
  p.track = !n.track_T.empty() && !p.track_request.amplitudes_um.empty();

  p.ablate_request = g.ablate;
  p.ablate_request.frequencies_Hz = keep(g.ablate.frequencies_Hz, n.ablate_f);
  p.ablate_request.threads = 1;
  p.ablate = !p.ablate_request.frequencies_Hz.empty();

  p.params_request = g.params;
  std::vector<double> pT = n.params_T;
  if (!g.params.temperatures_C.empty()) pT.push_back(g.params.temperatures_C.front());
  p.params_request.temperatures_C = keep(g.params.temperatures_C, pT);
  p.params_request.retention_currents_pp_A = keep(g.params.retention_currents_pp_A, n.retention_I);
  p.params_request.threads = 1;
  p.params = n.params;
}

void plan_metrics(ClaimPlan& p) {
  const SweepRequest d;
  for (const auto& q : p.metrics) {
    std::size_t k = 0;
    while (k < p.metric_points.size() &&
           !(same(p.metric_points[k].temperatures_C[0], q.temperature_C) &&
             same(p.metric_points[k].currents_pp_A[0], q.current_pp_A) &&
             same(p.metric_points[k].frequencies_Hz[0], q.frequency_Hz)))
      ++k;
    if (k == p.metric_points.size()) {
      // the sweep command's default settings at one point (the automatic step, not the
      // claims' step of the study's 10 Hz sweep), its own reference
      SweepRequest r = d;
      r.temperatures_C = {q.temperature_C};
      r.currents_pp_A = {q.current_pp_A};
      r.frequencies_Hz = {q.frequency_Hz};
      r.reference_temperature_C = q.temperature_C;
      r.threads = 1;
      p.metric_points.push_back(std::move(r));
    }
    p.metric_point_of.push_back(k);
  }
}

}  // namespace

StudyRequests reproduce_requests(bool quick) {
  StudyRequests g;
  if (quick) g.sweep_10Hz.temperatures_C = {20, 40, 70};
  // The claims' time step (claim_dt, issue 37's "one numerics": what gmasim identify's scalar
  // targets take): 25 us at 10 Hz; from 50 Hz up it is the automatic rule's (dt_s = 0).
  g.sweep_10Hz.dt_s = claim_dt(biased_sine(1.0, g.sweep_10Hz.frequencies_Hz.front()));
  g.params.dt_s = claim_dt(biased_sine(1.0, g.params.frequency_Hz));
  g.sweep_dynamic.temperatures_C =
      quick ? std::vector<double>{20, 70} : std::vector<double>{20, 30, 40, 50, 60, 70};
  g.sweep_dynamic.currents_pp_A = {6, 8};
  g.sweep_dynamic.frequencies_Hz = {100, 200, 400};
  if (quick) g.frf.points = 12;
  // Section 3.4's resonance amplitude: a stepped sine of +-1 A about the 1 A bias (our reading:
  // the paper gives no stimulus, and 0.1 mA would move y by under a nanometre), the markers
  // from the stepped sine (frf --method stepped --amplitude 1).
  g.frf_large.amplitude_A = 1.0;
  g.frf_large.small_signal = false;
  if (quick) g.frf_large.points = 12;
  if (quick) g.track.temperatures_C = {20, 40, 70};
  if (quick) g.params.temperatures_C = {20, 70, 150};
  return g;
}

ClaimPlan plan_claims(const ClaimsData& claims, bool quick, std::vector<MetricQuantity> metrics,
                      std::vector<FunctionQuantity> functions) {
  ClaimPlan p;
  p.quick = quick;
  p.claims = claims;
  p.grid = reproduce_requests(quick);
  p.metrics = std::move(metrics);
  p.functions = std::move(functions);
  Needs n;
  for (const auto& s : claims.claims) need(p.grid, s, n);
  p.full = n.full;
  if (!p.full) {
    p.sweeps_10Hz = split_sweep(p.grid.sweep_10Hz, n.sweep_10Hz);
    p.sweeps_dynamic = split_sweep(p.grid.sweep_dynamic, n.sweep_dynamic);
    plan_parts(n, p);
  }
  plan_metrics(p);
  // The most expensive first (measured per model on one core, all claims: the tracking runs
  // 0.6 s, the ablation 0.5 s, the 20-150 degC runs 0.4 s, the sweeps 0.4 s in all (0.05-0.1
  // s each), a metric run 0.05 s, the small-signal FRF 0.03 s).
  if (p.full) p.units.push_back({UnitKind::Full});
  if (p.track) p.units.push_back({UnitKind::Track});
  if (p.ablate) p.units.push_back({UnitKind::Ablate});
  if (p.params) p.units.push_back({UnitKind::Params});
  for (std::size_t k = 0; k < p.sweeps_10Hz.size(); ++k)
    p.units.push_back({UnitKind::Sweep10Hz, k});
  for (std::size_t k = 0; k < p.sweeps_dynamic.size(); ++k)
    p.units.push_back({UnitKind::SweepDynamic, k});
  for (std::size_t k = 0; k < p.metric_points.size(); ++k) p.units.push_back({UnitKind::Metric, k});
  if (p.frf) p.units.push_back({UnitKind::Frf});
  if (p.frf_large) p.units.push_back({UnitKind::FrfLarge});
  if (!p.functions.empty()) p.units.push_back({UnitKind::Functions});
  return p;
}

PartResults empty_results(const ClaimPlan& p) {
  PartResults r;
  r.sweeps_10Hz.resize(p.sweeps_10Hz.size());
  r.sweeps_dynamic.resize(p.sweeps_dynamic.size());
  r.metric_values.assign(p.metrics.size(), kNaN);
  r.function_values.assign(p.functions.size(), kNaN);
  r.errors.assign(p.units.size(), "");
  return r;
}

ClaimPlan with_lanes(ClaimPlan p, bool lanes) {
  for (auto* v : {&p.sweeps_10Hz, &p.sweeps_dynamic})
    for (SweepRequest& s : *v) s.lanes = lanes;
  p.ablate_request.lanes = lanes;
  p.params_request.lanes = lanes;
  p.lanes = lanes;
  return p;
}

std::string unit_name(const Unit& u) {
  switch (u.kind) {
    case UnitKind::Full:
      return "the whole study";
    case UnitKind::Track:
      return "tracking";
    case UnitKind::Ablate:
      return "ablation";
    case UnitKind::Params:
      return "20-150 degC runs";
    case UnitKind::Frf:
      return "FRF";
    case UnitKind::FrfLarge:
      return "large-signal FRF";
    case UnitKind::Sweep10Hz:
    case UnitKind::SweepDynamic:
      return "sweep";
    case UnitKind::Metric:
      return "metric run";
    case UnitKind::Functions:
      return "functions";
  }
  return "unit";
}

namespace {

// One metric point: the sweep's run (its settings) with the energy ledgers booked.
void run_metric_point(const ClaimPlan& p, std::size_t k, const Model& m, PartResults& out) {
  const SweepRequest& r = p.metric_points[k];
  SimulationSettings s;
  s.temperature_C = r.temperatures_C.front();
  s.waveform = biased_sine(r.currents_pp_A.front(), r.frequencies_Hz.front(), r.current_min_A);
  s.periods = r.periods;
  s.dt_s = r.dt_s;
  s.freeze = r.freeze;
  s.energy_ledger = true;
  const Result run = simulate(m, s);
  for (std::size_t q = 0; q < p.metrics.size(); ++q) {
    if (p.metric_point_of[q] != k) continue;
    out.metric_values[q] = run.diverged || !run.has_energy ? kNaN : p.metrics[q].read(run);
  }
  if (run.diverged) throw DivergenceError(run.error);
}

void run_unit_body(const ClaimPlan& p, const Unit& u, const Model& m, PartResults& out) {
  switch (u.kind) {
    case UnitKind::Full: {
      ReproduceOptions o;
      o.threads = 1;
      o.quick = p.quick;
      o.lanes = p.lanes;
      o.claims = &p.claims;
      out.full_claims = run_reproduce(m, o).claims;
      break;
    }
    case UnitKind::Track:
      out.track = run_track(m, p.track_request);
      break;
    case UnitKind::Ablate:
      out.ablate = run_ablate(m, p.ablate_request);
      break;
    case UnitKind::Params:
      out.params = run_params_vs_temperature(m, p.params_request);
      break;
    case UnitKind::Frf:
      out.frf = run_frf(m, p.frf_request);
      break;
    case UnitKind::FrfLarge:
      out.frf_large = run_frf(m, p.frf_large_request);
      break;
    case UnitKind::Sweep10Hz:
      out.sweeps_10Hz[u.index] = run_sweep(m, p.sweeps_10Hz[u.index]);
      break;
    case UnitKind::SweepDynamic:
      out.sweeps_dynamic[u.index] = run_sweep(m, p.sweeps_dynamic[u.index]);
      break;
    case UnitKind::Metric:
      run_metric_point(p, u.index, m, out);
      break;
    case UnitKind::Functions:
      for (std::size_t q = 0; q < p.functions.size(); ++q)
        out.function_values[q] = p.functions[q].evaluate(m);
      break;
  }
}

}  // namespace

void run_unit(const ClaimPlan& p, std::size_t u, const Model& m, PartResults& out) {
  try {
    run_unit_body(p, p.units[u], m, out);
  } catch (const DivergenceError& e) {
    out.errors[u] = fmt::format("{}: diverged: {}", unit_name(p.units[u]), e.what());
  } catch (const InputError& e) {
    out.errors[u] = fmt::format("{}: {}", unit_name(p.units[u]), e.what());
  }
}

std::vector<Claim> assemble_claims(const ClaimPlan& p, const Model& m, const PartResults& r) {
  std::vector<Claim> claims;
  if (p.full) {
    claims = r.full_claims;
  } else {
    ReproduceResult rr;
    rr.sweep_10Hz_request = p.grid.sweep_10Hz;
    rr.sweep_dynamic_request = p.grid.sweep_dynamic;
    for (const auto& s : r.sweeps_10Hz)
      rr.sweep_10Hz.points.insert(rr.sweep_10Hz.points.end(), s.points.begin(), s.points.end());
    for (const auto& s : r.sweeps_dynamic)
      rr.sweep_dynamic.points.insert(rr.sweep_dynamic.points.end(), s.points.begin(),
                                     s.points.end());
    rr.frf_request = p.frf_request;
    rr.frf = r.frf;
    rr.frf_large_request = p.frf_large_request;
    rr.frf_large = r.frf_large;
    rr.track_request = p.track_request;
    rr.track = r.track;
    rr.ablate_request = p.ablate_request;
    rr.ablate = r.ablate;
    rr.params_request = p.params_request;
    rr.params = r.params;
    rr.thermal = thermal_expansion_coefficient(m);
    claims = score_claims(rr, p.claims);
  }
  std::string failed;
  for (const auto& e : r.errors)
    if (!e.empty()) failed += (failed.empty() ? "" : "; ") + e;
  if (!failed.empty())
    for (auto& c : claims)
      if (c.applicable && !std::isfinite(c.ours)) c.note += (c.note.empty() ? "" : "; ") + failed;
  return claims;
}

}  // namespace gmasim::detail

namespace gmasim {

std::vector<Claim> run_claims(const Model& m, const ReproduceOptions& o,
                              const std::vector<std::string>& ids) {
  const ClaimsData& all = o.claims ? *o.claims : builtin_claims();
  ClaimsData chosen;
  chosen.source = all.source;
  if (ids.empty()) chosen.claims = all.claims;
  for (const auto& id : ids) {
    const ClaimSpec* s = all.find(id);
    if (!s) throw InputError(fmt::format("unknown claim '{}' (not in {})", id, all.source));
    chosen.claims.push_back(*s);
  }
  const detail::ClaimPlan p = detail::plan_claims(chosen, o.quick, {}, {});
  detail::PartResults r = detail::empty_results(p);
  detail::parallel_for(p.units.size(), resolve_thread_count(o.threads, p.units.size()),
                       [&](std::size_t u) { detail::run_unit(p, u, m, r); }, {});
  return detail::assemble_claims(p, m, r);
}

}  // namespace gmasim
