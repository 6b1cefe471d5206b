#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/model/self_heating.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "simulate/record.hpp"

namespace gmasim {

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

namespace {

// The run's grid (docs/model.md, "Time step"), after validate(): a uniform grid from t = 0.
struct RunLength {
  StepGrid grid;
  double duration_s = 0;
  double window_s = 0;  // not a biased sine: the metrics' window, the run's last window_s
};

// The metrics' window of a waveform that is not a biased sine (SimulationSettings::
// metrics_window_s): the given one, else a table's declared period, else the whole run.
// validate() has checked metrics_window_s itself.
double metrics_window(const SimulationSettings& s, double duration_s) {
  const auto& w = s.waveform;
  const double W = s.metrics_window_s > 0.0        ? s.metrics_window_s
                   : w.kind == WaveformKind::Table ? w.table_period_s
                                                   : 0.0;
  if (W == 0.0) return duration_s;
  if (W > duration_s * (1.0 + 1e-12))
    throw InputError(fmt::format(
        "metrics window = {:g} s ({}) is longer than the run, {:g} s: give a shorter window or a "
        "longer run (--duration)",
        W,
        s.metrics_window_s > 0.0 ? "--metrics-window"
                                 : "period_s of " + clip_for_message(w.table_source),
        duration_s));
  return std::min(W, duration_s);
}

// A step the user gave (dt_s, --dt): within [kMinStepDt_s, kMaxStepDt_s], and for a periodic
// run (or a chirp's highest frequency) at least kMinStepsPerPeriod steps per period.
void check_user_dt(const SimulationSettings& s) {
  if (s.dt_s == 0.0) return;
  const double dt = s.dt_s;
  if (dt < kMinStepDt_s || dt > kMaxStepDt_s)
    throw InputError(fmt::format(
        "dt = {:g} s (--dt, dt_s): must be in [{:g}, {:g}] s (a longer step resolves neither the "
        "eddy currents nor the mechanical modes, a shorter one no longer holds the state; "
        "docs/model.md, \"Time step\"); 0 = the automatic rule",
        dt, kMinStepDt_s, kMaxStepDt_s));
  const auto& w = s.waveform;
  double f = 0.0;
  if (w.periodic()) f = w.frequency_Hz;
  if (w.kind == WaveformKind::Chirp) f = std::max(w.f0_Hz, w.f1_Hz);
  if (f > 0.0 && 1.0 / (f * dt) < kMinStepsPerPeriod * (1.0 - 1e-9))
    throw InputError(fmt::format(
        "dt = {:g} s (--dt, dt_s) gives {:.4g} steps per period at {:g} Hz: at least {:g} are "
        "needed (the loop moves by more than 1 % when dt is halved below that; docs/model.md, "
        "\"Time step\"); lower --dt to <= {:.4g} s, or 0 for the automatic rule",
        dt, 1.0 / (f * dt), f, kMinStepsPerPeriod, 1.0 / (f * kMinStepsPerPeriod)));
}

RunLength run_length(const SimulationSettings& s) {
  const auto& w = s.waveform;
  check_user_dt(s);
  RunLength L;
  double dt = s.dt_s > 0.0 ? s.dt_s : auto_dt(w);
  double per_steps = 0.0;  // periodic: steps per period
  if (w.periodic()) {
    // Whole steps per period, so the last period's window is sampled exactly.
    const double per = w.period_s();
    const long n = steps_to_resolve(per / dt, 0, "steps per period");
    dt = per / static_cast<double>(n);
    per_steps = static_cast<double>(n);
    L.duration_s = s.periods * per;
  } else {
    L.duration_s = s.duration_s;
    if (L.duration_s == 0.0 && w.kind == WaveformKind::Table) L.duration_s = w.table_t_s.back();
    if (L.duration_s == 0.0 && w.kind == WaveformKind::Chirp) L.duration_s = w.duration_s;
    if (!(L.duration_s > 0.0))
      throw InputError(
          fmt::format("duration = {} s (--duration, duration_s): must be > 0", L.duration_s));
    if (L.duration_s < dt * (1.0 - 1e-9)) {
      // A table's own span, when no --duration was given, is the file's fault, not the flag's.
      if (s.duration_s == 0.0 && w.kind == WaveformKind::Table)
        throw InputError(fmt::format(
            "{}: the waveform spans {:g} s (its last time), shorter than one time step ({:g} s); "
            "give samples over a longer span, or --duration, or a shorter --dt",
            w.table_source.empty() ? std::string("waveform table")
                                   : clip_for_message(w.table_source),
            L.duration_s, dt));
      throw InputError(fmt::format(
          "duration = {:g} s (--duration): shorter than one time step ({:g} s); lengthen the run "
          "or give a shorter --dt",
          L.duration_s, dt));
    }
  }
  if (!w.periodic()) L.window_s = metrics_window(s, L.duration_s);
  L.grid = StepGrid::covering(
      0.0, L.duration_s, dt,
      w.kind == WaveformKind::Table && !w.table_source.empty()
          ? "simulation of " + clip_for_message(w.table_source) + " (its last time)"
          : std::string("simulation (--dt, --duration or --periods)"));
  const double rows = static_cast<double>(L.grid.steps) / s.record_every + 2.0;
  if (rows > kMaxRecordedRows)
    throw InputError(fmt::format(
        "simulation: {} steps recorded every {} give {:.4g} rows (limit {:g}); record less often "
        "(record_every, --record-every) or shorten the run",
        L.grid.steps, s.record_every, rows, kMaxRecordedRows));
  // The metrics' window (the last period, the given window, or the whole run) must hold enough
  // recorded samples.
  const bool whole = !w.periodic() && L.window_s == L.duration_s;
  const double window_steps = w.periodic() ? per_steps
                              : whole      ? static_cast<double>(L.grid.steps)
                                           : std::floor(L.window_s / L.grid.dt_s);
  const double samples = std::floor(window_steps / s.record_every) + (w.periodic() ? 0.0 : 1.0);
  if (samples < kMinMetricSamples)
    throw InputError(fmt::format(
        "record_every = {} (--record-every) with {:g} steps {} records {:g} sample(s) there: the "
        "metrics need at least {:g}; record more often{}",
        s.record_every, window_steps,
        w.periodic() ? "per period"
        : whole      ? "in the run"
                     : "in the metrics window",
        samples, kMinMetricSamples,
        w.periodic() ? "" : " or lengthen the window (--metrics-window) or the run (--duration)"));
  return L;
}

// Memory (issue 19, item 7): the recorded series (8 bytes a value) and, for the CLI, its CSV
// text twice over (the formatting buffer and the string, ~17 characters a value): 42 bytes a
// value. Refused before the run when that exceeds the memory available, naming the remedy.
constexpr double kRecordBytesPerValue = 8.0 + 2.0 * 17.0;

void check_record_memory(const Model& m, const SimulationSettings& s, const RunLength& L) {
  const double rows = static_cast<double>(L.grid.steps) / s.record_every + 2.0;
  const double columns = 6.0 + 9.0 * static_cast<double>(m.rods.size());
  const double bytes = rows * columns * kRecordBytesPerValue;
  if (bytes < 1e8) return;  // below 100 MB: not worth reading /proc
  const auto avail = memory_available();
  if (!avail || bytes <= avail->bytes) return;
  const double factor = std::max(2.0, std::ceil(bytes / (0.5 * avail->bytes)));
  require_memory(bytes,
                 fmt::format("simulation: recording {:.4g} rows x {:g} columns ({} steps, every "
                             "{}-th recorded)",
                             rows, columns, L.grid.steps, s.record_every),
                 fmt::format("record less often (--record-every {:g}, record_every) or shorten "
                             "the run",
                             static_cast<double>(s.record_every) * factor));
}

// The slower thermal clock of self-heating (gmasim/model/self_heating.hpp): accumulates the
// losses of each thermal step, advances the network, recomputes the Conditions at the rods'
// new temperature. The per-step work is allocation-free; the Conditions update once per
// thermal step is not (make_conditions).
struct SelfHeatingRun {
  bool enabled = false;
  long steps_per_interval = 0, in_interval = 0;
  double interval_s = 0, ambient_C = 0, T_ref_C = 20;
  const ThermalNetworkModel* net = nullptr;
  NodeTemperatures T, T0;
  double E_copper = 0, y_min = 0, y_max = 0, y_sum = 0, i_prev = 0;
  // The ledger's running sums of the rods' losses at the start of the interval [J].
  double E_eddy0 = 0, E_hyst0 = 0, E_damp0 = 0;

  SelfHeatingRun(const Model& m, const SimulationSettings& s, const RunLength& L, Result& r) {
    enabled = s.self_heating.enabled;
    if (!enabled) return;
    net = &m.thermal_network;
    T_ref_C = m.T_ref_C;
    const auto& h = s.self_heating;
    ambient_C = std::isnan(h.ambient_C) ? s.temperature_C : h.ambient_C;
    double want = h.thermal_step_s;
    if (want == 0.0) {
      want = 0.1;
      if (s.waveform.periodic())
        want = s.waveform.period_s() * std::ceil(0.1 / s.waveform.period_s() - 1e-9);
    }
    const double tau = fastest_time_constant_s(*net);
    auto too_long = [&](double step_s) {
      return InputError(
          fmt::format("thermal step (--thermal-step) = {:.4g} s: longer than the thermal network's "
                      "fastest time constant "
                      "{:.4g} s (min C/G over coil, rods, housing); shorten the thermal step",
                      step_s, tau));
    };
    // before the count: 1e14 s / 10 us overflowed lround's long, and the clamp made it 1 step
    if (!(want <= 2.0 * tau)) throw too_long(want);
    steps_per_interval = std::max(1L, std::lround(want / L.grid.dt_s));
    interval_s = static_cast<double>(steps_per_interval) * L.grid.dt_s;
    if (interval_s > tau) throw too_long(interval_s);
    T = T0 = {s.temperature_C, s.temperature_C, s.temperature_C};
    r.heating.names = {"t_s",      "coil_C",         "rods_C",      "housing_C",   "P_copper_W",
                       "P_eddy_W", "P_hysteresis_W", "P_damping_W", "P_ambient_W", "stroke_um",
                       "E_in_J",   "E_stored_J",     "E_out_J",     "xT_um",       "y_mean_um"};
    r.heating.columns.assign(r.heating.names.size(), {});
    const double rows =
        static_cast<double>(L.grid.steps) / static_cast<double>(steps_per_interval) + 2;
    for (auto& col : r.heating.columns) col.reserve(static_cast<std::size_t>(rows));
  }

  static constexpr std::size_t kXtColumn = 13;  // xT_um in r.heating.names
  // A row of self_heating.csv; xT_um (eq. 21 at the row's rods temperature) and y_mean_um (the
  // output's mean over it) are the offset drift beside the stroke (issue 20).
  void push_row(Result& r, double t, double Pc, double Pe, double Ph, double Pd, double Pa,
                double stroke, double xT_um, double y_mean_um) {
    const double row[] = {
        t,      T.coil_C,      T.rods_C,          T.housing_C,    Pc,    Pe,       Ph, Pd, Pa,
        stroke, r.energy_in_J, r.energy_stored_J, r.energy_out_J, xT_um, y_mean_um};
    for (std::size_t j = 0; j < r.heating.columns.size(); ++j)
      r.heating.columns[j].push_back(row[j]);
  }

  static void rod_losses(const State& st, double& eddy, double& hyst, double& damp) {
    eddy = hyst = damp = 0.0;
    for (const auto& rs : st.rods) {
      eddy += rs.energy.eddy_J;
      hyst += rs.energy.hysteresis_J;
      damp += rs.energy.damping_J;
    }
  }

  void begin(const Conditions& c, const State& st, Result& r) {
    if (!enabled) return;
    i_prev = st.current_A;
    y_min = y_max = st.y_m;
    rod_losses(st, E_eddy0, E_hyst0, E_damp0);
    push_row(r, st.t_s, 0, 0, 0, 0, 0, 0, c.thermal_expansion_m * 1e6, st.y_m * 1e6);
  }

  void after_step(const Model& m, const SimulationSettings& s, Conditions& c, const State& st,
                  double dt, bool last, Result& r) {
    E_copper +=
        copper_loss_J(i_prev, st.current_A, coil_resistance_ohm(*net, T_ref_C, T.coil_C), dt);
    i_prev = st.current_A;
    y_min = std::min(y_min, st.y_m);
    y_max = std::max(y_max, st.y_m);
    y_sum += st.y_m;
    if (++in_interval < steps_per_interval && !last) return;
    // One thermal step: the interval's mean powers heat the network. The rods' losses are the
    // energy ledger's hysteresis, eddy-current and damping terms (gmasim/model/energy.hpp), each
    // >= 0 by its own law.
    const double span = static_cast<double>(in_interval) * dt;
    double eddy = 0, hyst = 0, damp = 0;
    rod_losses(st, eddy, hyst, damp);
    const double Pc = E_copper / span, Pe = (eddy - E_eddy0) / span, Ph = (hyst - E_hyst0) / span,
                 Pd = (damp - E_damp0) / span;
    const double E_out = thermal_network_step(*net, T, Pc, Pe + Ph + Pd, ambient_C, span);
    r.energy_in_J += (Pc + Pe + Ph + Pd) * span;
    r.energy_out_J += E_out;
    r.energy_stored_J = stored_heat_J(*net, T, T0);
    push_row(r, st.t_s, Pc, Pe, Ph, Pd, E_out / span, (y_max - y_min) * 1e6,
             c.thermal_expansion_m * 1e6, y_sum / static_cast<double>(in_interval) * 1e6);
    y_sum = 0;
    in_interval = 0;
    E_copper = 0;
    E_eddy0 = eddy;
    E_hyst0 = hyst;
    E_damp0 = damp;
    y_min = y_max = st.y_m;
    try {
      c = make_conditions(m, T.rods_C, s.freeze);
      // x_T of the row: at the rods' temperature of its end, as the series records it.
      r.heating.columns[kXtColumn].back() = c.thermal_expansion_m * 1e6;
    } catch (const InputError& e) {
      throw DivergenceError(fmt::format(
          "self-heating: at t = {:.6g} s the rods reached {:.2f} degC, where the model is not "
          "defined ({})",
          st.t_s, T.rods_C, e.what()));
    }
  }
};

// The energy ledgers over the metrics window: a snapshot at its start, the coil's terminal
// quantities summed over its steps, the balance at its end.
struct EnergyWindow {
  bool enabled = false;
  long start_step = 0;  // the snapshot is taken after this step (0: before the first)
  long end_step = 0;    // ... and after this one, before self-heating updates the Conditions
  EnergySnapshot from, to;
  long n = 0;
  double R_ohm = 0, i_prev = 0;
  double sum_i2 = 0, sum_v2 = 0, v_peak = 0, p_peak = 0, copper_J = 0, dt_s = 0;

  // After step k, before self-heating may replace the Conditions: books the coil's terms and,
  // at the window's end, the closing snapshot.
  void at(const Model& m, const Conditions& c, const State& st, long k, double dt) {
    if (!enabled || k <= start_step) return;
    const double i_mid = 0.5 * (i_prev + st.current_A);
    const double v = i_mid * R_ohm + st.energy.coil_emf_V;
    sum_i2 += i_mid * i_mid;
    sum_v2 += v * v;
    v_peak = std::max(v_peak, std::fabs(v));
    p_peak = std::max(p_peak, std::fabs(i_mid * v));
    copper_J += copper_loss_J(i_prev, st.current_A, R_ohm, dt);
    i_prev = st.current_A;
    dt_s = dt;
    ++n;
    if (k == end_step) to = energy_snapshot(m, c, st);
  }

  // After step k and the self-heating update: the opening snapshot, with the Conditions the
  // window's steps use.
  void open(const Model& m, const Conditions& c, const State& st, long k) {
    if (!enabled || k != start_step) return;
    from = energy_snapshot(m, c, st);
    i_prev = st.current_A;
  }

  void finish(Result& r) const {
    if (!enabled || n == 0) return;
    r.energy = energy_balance(from, to);
    const double span = r.energy.duration_s, N = static_cast<double>(n);
    auto& e = r.coil;
    e.resistance_ohm = R_ohm;
    e.current_rms_A = std::sqrt(sum_i2 / N);
    e.voltage_rms_V = std::sqrt(sum_v2 / N);
    e.voltage_peak_V = v_peak;
    e.power_peak_W = p_peak;
    e.copper_W = copper_J / span;
    e.power_mean_W = e.copper_W + r.energy.coil_J / span;
    e.apparent_VA = e.voltage_rms_V * e.current_rms_A;
    r.has_energy = true;
  }
};

// What simulate() does after each step: self-heating (which may replace the Conditions the
// loop reads), the decimated record, the step count and the progress callback.
struct SimulationRecorder {
  const Model& m;
  const SimulationSettings& s;
  Conditions& c;  // the object run_loop() reads at every step
  SelfHeatingRun& heat;
  EnergyWindow& energy;
  MetricsWindow& window;
  Result& r;
  long nsteps, report_every;

  void operator()(const State& st, const StepPoint& p) {
    const long k = p.k;
    energy.at(m, c, st, k, p.dt_s);
    if (heat.enabled) heat.after_step(m, s, c, st, p.dt_s, k == nsteps, r);
    energy.open(m, c, st, k);
    if (k % s.record_every == 0 || k == nsteps) {
      if (!window.enabled())
        record(c, st, r.series);
      else if (k >= window.first)
        window.push(st);
    }
    r.steps = k;
    if (s.progress && (k % report_every == 0 || k == nsteps))
      s.progress(static_cast<std::size_t>(k), static_cast<std::size_t>(nsteps));
  }
};

}  // namespace

void validate(const Waveform& w) {
  auto current = [](double v, const char* what) {
    require_in(v, -kMaxCurrent_A, kMaxCurrent_A, what, "A");
  };
  auto frequency = [](double v, const char* what) {
    require_positive_at_most(v, kMaxFrequency_Hz, what, "Hz");
  };
  switch (w.kind) {
    case WaveformKind::BiasedSine:
      frequency(w.frequency_Hz, "frequency");
      current(w.min_A, "current minimum");
      require_in(w.pp_A, 0.0, 2.0 * kMaxCurrent_A, "current peak-to-peak", "A");
      current(w.min_A + w.pp_A, "current maximum");
      break;
    case WaveformKind::DC:
      current(w.level_A, "current level");
      break;
    case WaveformKind::Step:
      current(w.level_A, "current level");
      current(w.step_to_A, "step current");
      require_finite(w.step_time_s, "step time", "s");

      break;
    case WaveformKind::Chirp:
      current(w.offset_A, "chirp offset");
      require_in(w.amplitude_A, 0.0, kMaxCurrent_A, "chirp amplitude", "A");
      current(w.offset_A + w.amplitude_A, "chirp maximum (offset + amplitude)");
      current(w.offset_A - w.amplitude_A, "chirp minimum (offset - amplitude)");
      frequency(w.f0_Hz, "chirp start frequency");
      frequency(w.f1_Hz, "chirp end frequency");
      require_positive(w.duration_s, "chirp duration", "s");
      break;
    case WaveformKind::Table: {
      const std::string src = w.table_source.empty() ? "waveform table" : w.table_source;
      if (w.table_t_s.empty() || w.table_t_s.size() != w.table_current_A.size())
        throw InputError(fmt::format("{}: needs equally long, non-empty t_s and current_A", src));
      for (std::size_t k = 0; k < w.table_t_s.size(); ++k) {
        require_finite(w.table_t_s[k], src + ": t_s", "s");
        if (!(std::fabs(w.table_current_A[k]) <= kMaxCurrent_A))  // named only when it fails
          current(w.table_current_A[k], fmt::format("{}: sample {} (t = {:g} s): waveform current",
                                                    src, k + 1, w.table_t_s[k])
                                            .c_str());
        if (k > 0 && !(w.table_t_s[k] > w.table_t_s[k - 1]))
          throw InputError(fmt::format("{}: time {:g} s does not increase (previous {:g} s)", src,
                                       w.table_t_s[k], w.table_t_s[k - 1]));
      }
      // The run starts at t = 0: a table that starts later would be held at its first value
      // for that long, a silent prefix nobody asked for; one that starts earlier is cut.
      if (w.table_t_s.front() != 0.0)
        throw InputError(fmt::format(
            "{}: starts at t = {:g} s; a waveform table must start at t = 0 (the run starts "
            "there): subtract {:g} s from t_s",
            src, w.table_t_s.front(), w.table_t_s.front()));
      break;
    }
  }
}

void validate(const SimulationSettings& s) {
  require_finite(s.temperature_C, "temperature", "degC");
  validate(s.waveform);
  if (!(s.dt_s >= 0.0) || !std::isfinite(s.dt_s))
    throw InputError(
        fmt::format("dt = {} s (--dt, dt_s): must be > 0 (or 0 for the automatic rule)", s.dt_s));
  if (s.record_every < 1)
    throw InputError(
        fmt::format("record_every = {} (--record-every): must be >= 1", s.record_every));
  if (s.waveform.periodic()) {
    require_finite(s.periods, "periods");
    if (!(s.periods >= 1.0))
      throw InputError(fmt::format("periods = {} (--periods): must be >= 1", s.periods));
    require_in(s.periods, 1.0, kMaxPeriods, "periods (--periods)");
  }
  require_nonnegative(s.duration_s, "duration", "s");
  if (!(s.metrics_window_s >= 0.0) || !std::isfinite(s.metrics_window_s))
    throw InputError(fmt::format(
        "metrics window = {} s (--metrics-window, metrics_window_s): must be >= 0 (0: {})",
        s.metrics_window_s, "a table's declared period, else the whole run"));
  if (s.waveform.periodic() && s.metrics_window_s != 0.0)
    throw InputError(fmt::format(
        "metrics window = {:g} s (--metrics-window): a biased sine's metrics are over its last "
        "period; the window is for the other waveforms (dc, step, chirp, a CSV table)",
        s.metrics_window_s));
  const RunLength L = run_length(s);
  // A step at t <= 0 is not one (the rest state is made at current_at(0), the step's current),
  // nor is one at or after the run's end: either ran with no step and a zero stroke.
  if (s.waveform.kind == WaveformKind::Step &&
      !(s.waveform.step_time_s > 0.0 && s.waveform.step_time_s < L.duration_s))
    throw InputError(fmt::format(
        "step time = {:g} s (--step-time): must be inside the run, 0 < t < {:g} s (the duration): "
        "at t <= 0 the rest state is already at the step's current, after the end nothing steps",
        s.waveform.step_time_s, L.duration_s));
  if (s.self_heating.enabled) {
    const auto& h = s.self_heating;
    require_nonnegative(h.thermal_step_s, "thermal step", "s");
    if (!std::isnan(h.ambient_C))
      require_in(h.ambient_C, -273.15, 1e4, "ambient temperature", "degC");
    if (h.thermal_step_s > 0.0 && h.thermal_step_s < L.grid.dt_s)
      throw InputError(
          fmt::format("thermal step = {} s (--thermal-step): shorter than the time step {} s",
                      h.thermal_step_s, L.grid.dt_s));
  }
}

namespace {

// simulate(), or, metrics_only (a periodic run without energy ledger or self-heating), the same
// run recording only the metrics' window (MetricsWindow).
Result run_simulation(const Model& m, const SimulationSettings& s, bool metrics_only) {
  const auto& w = s.waveform;
  validate(s);
  const RunLength L = run_length(s);
  check_record_memory(m, s, L);
  const double duration = L.duration_s;
  const long nsteps = L.grid.steps;

  Conditions c = make_conditions(m, s.temperature_C, s.freeze);
  Result r;
  r.dt_s = L.grid.dt_s;
  r.thermal_expansion_start_um = r.thermal_expansion_um = c.thermal_expansion_m * 1e6;
  MetricsWindow window;
  if (metrics_only && w.periodic() && !s.energy_ledger && !s.self_heating.enabled)
    window.start(nsteps, std::lround(w.period_s() / L.grid.dt_s), s.record_every);
  else
    make_columns(m, r.series, static_cast<std::size_t>(nsteps / s.record_every + 2));
  SelfHeatingRun heat(m, s, L, r);
  EnergyWindow energy;
  energy.enabled = s.energy_ledger || s.self_heating.enabled;
  if (w.periodic()) energy.start_step = nsteps - std::lround(w.period_s() / L.grid.dt_s);
  if (!w.periodic() && L.window_s < duration)
    energy.start_step = std::max(0L, nsteps - std::lround(L.window_s / L.grid.dt_s));
  energy.end_step = nsteps;
  energy.R_ohm = coil_resistance_ohm(m.thermal_network, m.T_ref_C, s.temperature_C);
  const auto wall0 = std::chrono::steady_clock::now();
  try {
    State st = make_state(m, c, w.current_at(0.0));
    st.energy.enabled = energy.enabled;
    check_physical_validity(m, c, st, 0.0);  // the rest state too (gmasim/model/validity.hpp)
    if (!window.enabled())
      record(c, st, r.series);
    else if (window.first <= 0)
      window.push(st);
    energy.open(m, c, st, 0);
    heat.begin(c, st, r);
    run_loop(
        m, c, st, L.grid, [&w](double t) { return w.current_at(t); },
        SimulationRecorder{m, s, c, heat, energy, window, r, nsteps, std::max(1L, nsteps / 100)});
    energy.finish(r);
  } catch (const DivergenceError& e) {
    r.diverged = true;
    r.error = e.what();
  }
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  // Self-heating moves the expansion: the value at the end of the run (the last row's xT_um).
  if (r.series.rows() > 0) r.thermal_expansion_um = r.series.column("xT_um").back();
  if (!r.diverged && window.enabled()) {
    const double per = w.period_s();
    r.metrics = window.metrics(duration - per, duration);
    r.has_metrics = true;
  } else if (!r.diverged && w.periodic()) {
    const double per = w.period_s();
    r.metrics = compute_metrics(r.series, duration - per, duration);
    r.has_metrics = true;
  } else if (!r.diverged && r.series.rows() >= 3) {
    r.metrics =
        compute_metrics(r.series, L.window_s < duration ? duration - L.window_s : 0.0, duration);
    r.has_metrics = true;
    if (w.kind == WaveformKind::Step) r.step = step_metrics(r.series, w.step_time_s);
  }
  return r;
}

}  // namespace

Result simulate(const Model& m, const SimulationSettings& s) { return run_simulation(m, s, false); }

Result simulate_metrics_only(const Model& m, const SimulationSettings& s) {
  return run_simulation(m, s, true);
}

}  // namespace gmasim
