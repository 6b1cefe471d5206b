#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/simulate.hpp"

namespace gmasim {
namespace {

// Column layout of the recorded series: global columns, then per rod.
constexpr int kGlobal = 6;  // t_s, current_A, y_um, B_T, xT_um, y_stack_um
constexpr int kPerRod = 9;  // H, M, mu_r, E_G, lambda, F, x, tau, B

void make_columns(const Model& m, TimeSeries& ts, std::size_t reserve) {
  ts.names = {"t_s", "current_A", "y_um", "B_T", "xT_um", "y_stack_um"};
  for (const auto& r : m.rods) {
    for (const char* q : {"_H_A_per_m", "_M_A_per_m", "_mu_r", "_E_GPa", "_lambda_ppm", "_F_N",
                          "_x_um", "_tau_eddy_ms", "_B_T"})
      ts.names.push_back(r.name + q);
  }
  ts.columns.assign(ts.names.size(), {});
  for (auto& c : ts.columns) c.reserve(reserve);
}

void record(const Conditions& c, const State& s, TimeSeries& ts) {
  auto& col = ts.columns;
  col[0].push_back(s.t_s);
  col[1].push_back(s.current_A);
  col[2].push_back(s.y_m * 1e6);
  col[3].push_back(s.B_T);
  col[4].push_back(c.thermal_expansion_m * 1e6);
  col[5].push_back(s.y_stack_m * 1e6);
  for (std::size_t i = 0; i < s.rods.size(); ++i) {
    const auto& r = s.rods[i];
    const std::size_t b = kGlobal + i * kPerRod;
    col[b + 0].push_back(r.H_A_per_m);
    col[b + 1].push_back(r.M_A_per_m);
    col[b + 2].push_back(r.mu_r);
    col[b + 3].push_back(r.E_Pa * 1e-9);
    col[b + 4].push_back(r.lambda * 1e6);
    col[b + 5].push_back(r.F_N);
    col[b + 6].push_back(r.x_m * 1e6);
    col[b + 7].push_back(r.tau_s * 1e3);
    col[b + 8].push_back(r.B_T);
  }
}

}  // namespace

Result simulate(const Model& m, const SimulationSettings& s) {
  const auto& w = s.waveform;
  if (w.periodic() && !(w.frequency_Hz > 0.0 && std::isfinite(w.frequency_Hz)))
    throw InputError(fmt::format("frequency {} Hz: must be > 0", w.frequency_Hz));
  if (w.kind == WaveformKind::BiasedSine && !(w.pp_A >= 0.0 && std::isfinite(w.pp_A)))
    throw InputError(fmt::format("current peak-to-peak {} A: must be >= 0", w.pp_A));
  if (!(s.dt_s >= 0.0) || !std::isfinite(s.dt_s))
    throw InputError(fmt::format("dt {} s: must be > 0 (or 0 for the automatic rule)", s.dt_s));
  if (s.record_every < 1)
    throw InputError(fmt::format("record_every {}: must be >= 1", s.record_every));

  double duration = 0.0;
  double dt = s.dt_s > 0.0 ? s.dt_s : auto_dt(w);
  if (w.periodic()) {
    if (!(s.periods >= 1.0)) throw InputError(fmt::format("periods {}: must be >= 1", s.periods));
    // Whole steps per period, so the last period's window is sampled exactly.
    const double per = w.period_s();
    const double steps_per_period = std::ceil(per / dt - 1e-9);
    dt = per / steps_per_period;
    duration = s.periods * per;
  } else {
    duration = s.duration_s;
    if (duration == 0.0 && w.kind == WaveformKind::Table) duration = w.table_t_s.back();
    if (duration == 0.0 && w.kind == WaveformKind::Chirp) duration = w.duration_s;
    if (!(duration > 0.0)) throw InputError(fmt::format("duration {} s: must be > 0", duration));
  }
  const long nsteps = std::lround(duration / dt);
  if (nsteps > 200'000'000L)
    throw InputError(fmt::format(
        "{} steps of {} s: too many (limit 2e8); raise dt or shorten the run", nsteps, dt));

  const Conditions c = make_conditions(m, s.temperature_C, s.freeze);
  Result r;
  r.dt_s = dt;
  r.thermal_expansion_um = c.thermal_expansion_m * 1e6;
  make_columns(m, r.series, static_cast<std::size_t>(nsteps / s.record_every + 2));
  const auto wall0 = std::chrono::steady_clock::now();
  try {
    State st = make_state(m, c, w.current_at(0.0));
    record(c, st, r.series);
    for (long k = 1; k <= nsteps; ++k) {
      const double t = static_cast<double>(k) * dt;
      step(m, c, st, {w.current_at(t), dt});
      st.t_s = t;  // avoid drift from repeated addition
      if (k % s.record_every == 0 || k == nsteps) record(c, st, r.series);
      r.steps = k;
    }
  } catch (const DivergenceError& e) {
    r.diverged = true;
    r.error = e.what();
  }
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (!r.diverged && w.periodic()) {
    const double per = w.period_s();
    r.metrics = compute_metrics(r.series, duration - per, duration);
    r.has_metrics = true;
  }
  return r;
}

}  // namespace gmasim
