// The simulations of the identification objective besides its records (objective_runs.hpp),
// and simulate_measurement().
#include "identify/objective_runs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/frf_bias.hpp"
#include "gmasim/mechanics/mechanics.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "identify/record_run.hpp"

namespace gmasim {
namespace identify_detail {

const std::pair<Conditions, State>& StartCache::get(double T, double I0) {
  for (const auto& e : entries_)
    if (e.T == T && e.I0 == I0) return e.cs;
  Conditions c = make_conditions(m_, T);
  State st = make_state(m_, c, I0);
  entries_.push_back({T, I0, {std::move(c), std::move(st)}});
  return entries_.back().cs;
}

std::vector<std::pair<double, double>> StartCache::missing(
    const std::vector<std::pair<double, double>>& T_I0) const {
  std::vector<std::pair<double, double>> todo;
  for (const auto& k : T_I0) {
    bool cached = std::find(todo.begin(), todo.end(), k) != todo.end();
    for (const auto& e : entries_) cached = cached || (e.T == k.first && e.I0 == k.second);
    if (!cached) todo.push_back(k);
  }
  return todo;
}

std::vector<State> StartCache::make_in_lanes(const std::vector<std::pair<double, double>>& T_I0,
                                             const std::vector<const Conditions*>& extra_c,
                                             const std::vector<double>& extra_I0) {
  StartCache* const self = this;
  return std::move(make_in_lanes({self}, T_I0, {extra_c}, {extra_I0})[0]);
}

std::vector<std::vector<State>> StartCache::make_in_lanes(
    const std::vector<StartCache*>& caches, const std::vector<std::pair<double, double>>& T_I0,
    const std::vector<std::vector<const Conditions*>>& extra_c,
    const std::vector<std::vector<double>>& extra_I0) {
  const std::size_t P = caches.size();
  std::vector<std::vector<State>> extra(P);
  std::vector<std::vector<std::pair<double, double>>> todo(P);
  std::deque<Conditions> conds;  // stable addresses
  std::vector<const Model*> models;
  std::vector<const Conditions*> cp;
  std::vector<double> I0;
  std::vector<std::size_t> in_lanes;  // the caches whose ramps take the lanes
  for (std::size_t p = 0; p < P; ++p) {
    StartCache& sc = *caches[p];
    todo[p] = sc.missing(T_I0);
    const std::size_t ne = extra_c[p].size();
    if (todo[p].size() + ne < 2) {  // one ramp: make_state, no lanes to share
      for (std::size_t k = 0; k < ne; ++k)
        extra[p].push_back(make_state(sc.m_, *extra_c[p][k], extra_I0[p][k]));
      continue;
    }
    in_lanes.push_back(p);
    for (const auto& [T, I] : todo[p]) {
      conds.push_back(make_conditions(sc.m_, T));
      cp.push_back(&conds.back());
      I0.push_back(I);
    }
    cp.insert(cp.end(), extra_c[p].begin(), extra_c[p].end());
    I0.insert(I0.end(), extra_I0[p].begin(), extra_I0[p].end());
    models.insert(models.end(), todo[p].size() + ne, &sc.m_);
  }
  if (in_lanes.empty()) return extra;
  std::vector<State> st = make_states(models, cp, I0);
  std::size_t at = 0;
  for (std::size_t p : in_lanes) {
    StartCache& sc = *caches[p];
    for (const auto& [T, I] : todo[p]) {
      sc.entries_.push_back({T, I, {std::move(conds.front()), std::move(st[at++])}});
      conds.pop_front();
    }
    for (std::size_t k = 0; k < extra_c[p].size(); ++k) extra[p].push_back(std::move(st[at++]));
  }
  return extra;
}

// A scalar target's run takes the claims' time step (claim_dt: the step gmasim reproduce
// scores the claims with, issue 37's "one numerics"), not the records' --dt or
// --steps-per-period, and whole steps per period as simulate() makes them.
SineGrid sine_target_grid(const SineRun& run, const ObjectiveSettings& s) {
  const double per = 1.0 / run.f;
  SineGrid g;
  g.per_period =
      steps_to_resolve(per / claim_dt(biased_sine(run.pp, run.f, run.min)), 8, "steps per period");
  const long periods = std::max(1L, checked_count(s.target_periods, 1e4, "target periods"));
  g.grid = StepGrid::uniform(0.0, per / static_cast<double>(g.per_period),
                             static_cast<double>(periods) * static_cast<double>(g.per_period),
                             fmt::format("steps of the {:g} Hz target simulation", run.f));
  return g;
}

std::vector<double> sine_drive(const SineRun& run, const ObjectiveSettings& s) {
  const SineGrid g = sine_target_grid(run, s);
  if (g.grid.steps > kMaxStoredDriveSteps) return {};
  const Waveform w = biased_sine(run.pp, run.f, run.min);
  std::vector<double> d(static_cast<std::size_t>(g.grid.steps) + 1);
  for (long q = 0; q <= g.grid.steps; ++q)  // run_sines_lanes's times, t0 + q dt
    d[static_cast<std::size_t>(q)] =
        w.current_at(g.grid.t0_s + static_cast<double>(q) * g.grid.dt_s);
  return d;
}

SineMetrics run_sine(const Model& m, const SineRun& run, const ObjectiveSettings& s,
                     std::vector<double>& I, std::vector<double>& y, std::vector<double>& B,
                     StartCache& starts) {
  const Waveform w = biased_sine(run.pp, run.f, run.min);
  const SineGrid g = sine_target_grid(run, s);
  const long n_per = g.per_period, total = g.grid.steps;
  const auto& [c, st0] = starts.get(run.T, w.current_at(0.0));
  State st = st0;
  const auto rows = static_cast<std::size_t>(n_per) + 1;  // the last period and its closing row
  I.assign(rows, 0.0);
  y.assign(rows, 0.0);
  B.assign(rows, 0.0);
  const long first = total - n_per;  // record samples k in [first, total]
  auto rec = [&](const State& x, long k) {
    if (k < first || k > total) return;
    const auto i = static_cast<std::size_t>(k - first);
    I[i] = x.current_A;
    y[i] = x.y_m * 1e6;
    B[i] = x.B_T;
  };
  rec(st, 0);
  run_loop(
      m, c, st, g.grid, [&w](double t) { return w.current_at(t); },
      [&](const State& x, const StepPoint& p) { rec(x, p.k); });
  std::vector<double> t(rows);  // uniform: only the spacing matters to the refinement
  for (std::size_t k = 0; k < rows; ++k) t[k] = static_cast<double>(k);
  const LoopMetrics L = loop_metrics(t, I, y, B, 0, rows - 1, run.want);
  SineMetrics r;
  r.stroke_um = L.stroke_um;
  r.B_pp_T = L.B_pp_T;
  r.hysteresis_um = L.hysteresis_um;
  return r;
}

double lowest_resonance_Hz(const Model& m, const ResonanceRun& run, StartCache& starts,
                           const BiasRamp* ramp) {
  if (run.kind == TargetKind::ModulusGPa) {  // eq. (13) at rest, mean over the rods
    const State& st = starts.get(run.T, run.bias).second;
    double E = 0.0;
    for (const auto& r : st.rods) E += r.E_Pa;
    return E / static_cast<double>(st.rods.size()) * 1e-9;
  }
  if (run.kind != TargetKind::ResonanceHz) {  // the small-signal frequency response (Fig. 15)
    // run_frf's linearised markers without the rest of its curve (the same numbers; from the
    // ramp made in lanes, to their rounding).
    LinearFrfMarkers lm;
    if (!ramp) {
      lm = linear_frf_markers(m, run.T, run.bias);
    } else if (ramp->settled) {
      State settled = ramp->ramped;
      settled.t_s = 0.0;  // as settle_at_bias_from leaves it
      lm = linear_frf_markers_at(m, ramp->c, settled);
    } else {
      lm = linear_frf_markers_at(
          m, ramp->c,
          settle_at_bias_from(m, ramp->c, ramp->ramped, run.bias, FrfRequest{}.bias_state));
    }
    return run.kind == TargetKind::FrfPeakHz ? lm.first_resonance_Hz : lm.bandwidth_3dB_Hz;
  }
  const auto& [c, st] = starts.get(run.T, run.bias);
  double f = std::numeric_limits<double>::infinity();
  for (int i = 0; i < m.rod_count(); ++i) {
    const double K = oscillator_stiffness(c, st, i);
    const double mass = c.rods[static_cast<std::size_t>(i)].mass_osc_kg;
    f = std::min(f, std::sqrt(K / mass) / (2.0 * physics::kPi));
  }
  return f;
}

std::vector<HeldRun> settlings_beside_sines(const Model& m, const std::vector<SineRun>& sines,
                                            const ObjectiveSettings& s,
                                            const std::vector<ResonanceRun>& res_runs,
                                            std::deque<BiasRamp>& ramps) {
  long longest = 0;
  for (const auto& run : sines) longest = std::max(longest, sine_target_grid(run, s).grid.steps);
  const BiasState bias_state = FrfRequest{}.bias_state;
  std::vector<std::size_t> which;
  std::vector<State> start;
  for (std::size_t k = 0; k < res_runs.size(); ++k) {
    const ResonanceRun& run = res_runs[k];
    if (run.kind != TargetKind::FrfPeakHz && run.kind != TargetKind::BandwidthHz) continue;
    start.push_back(bias_settling_start(m, ramps[k].c, ramps[k].ramped, run.bias, bias_state));
    if (bias_settling_grid(start.back()).steps > longest) return {};
    which.push_back(k);
  }
  const auto W = static_cast<std::size_t>(lanes_width());
  const std::size_t ns = sines.size(), nh = which.size();
  if (nh == 0 || (ns + nh + W - 1) / W > (ns + W - 1) / W) return {};
  std::vector<HeldRun> held;
  for (std::size_t j = 0; j < nh; ++j) {
    BiasRamp& r = ramps[which[j]];
    r.ramped = std::move(start[j]);
    r.settled = true;
    held.push_back({&r.c, &r.ramped, res_runs[which[j]].bias, bias_settling_grid(r.ramped)});
  }
  return held;
}

void run_record_from_start(const Model& m, StartCache& starts, const Measurement& meas,
                           const ObjectiveSettings& s, std::vector<double>& response,
                           std::vector<double>* B_T) {
  const double T = meas.condition.temperature_C, I0 = record_initial_current(meas);
  if (std::isnan(meas.condition.prestress_MPa)) {
    const auto& [c, st] = starts.get(T, I0);
    run_record(m, c, st, meas, s, response, B_T);
    return;
  }
  const Model mp = with_record_preload(m, meas.condition);
  const Conditions c = make_conditions(mp, T);
  run_record(mp, c, make_state(mp, c, I0), meas, s, response, B_T);
}

void bias_ramps(const Model& model, const std::vector<ResonanceRun>& res_runs,
                std::deque<BiasRamp>& ramps, std::vector<const Conditions*>& rc,
                std::vector<double>& I0, std::vector<std::size_t>& which) {
  ramps.resize(res_runs.size());
  const FrfRequest frf;
  for (std::size_t k = 0; k < res_runs.size(); ++k) {
    const ResonanceRun& run = res_runs[k];
    if (run.kind != TargetKind::FrfPeakHz && run.kind != TargetKind::BandwidthHz) continue;
    ramps[k].c = make_conditions(model, run.T);
    ramps[k].ramp_c = bias_ramp_conditions(model, ramps[k].c, frf.bias_state);
    rc.push_back(&ramps[k].ramp_c);
    I0.push_back(run.bias);
    which.push_back(k);
  }
}

}  // namespace identify_detail

void simulate_measurement(const Model& m, const Measurement& meas, const ObjectiveSettings& s,
                          std::vector<double>& y_um, std::vector<double>* B_T) {
  identify_detail::StartCache starts(m);
  identify_detail::run_record_from_start(m, starts, meas, s, y_um, B_T);
}

}  // namespace gmasim
