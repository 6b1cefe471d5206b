// gmasim track (Fig. 16): closed-loop displacement tracking with the paper's PID, a
// discrete controller with a sampled displacement sensor driving the coil current.
// docs/experiments.md, "Closed-loop tracking".
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>

#include "experiments/parallel.hpp"
#include "experiments/track_loop.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/feedforward.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

// ---------------------------------------------------------------------------------------
// PID
// ---------------------------------------------------------------------------------------
Pid::PerSample Pid::per_sample(const PidGains& g, double sample_rate_Hz) {
  return {g.kp, g.ki * g.reference_rate_Hz / sample_rate_Hz,
          g.kd * sample_rate_Hz / g.reference_rate_Hz};
}

Pid::Pid(const PidGains& g, double sample_rate_Hz, double u_min, double u_max)
    : u_min_(u_min), u_max_(u_max) {
  const PerSample k = per_sample(g, sample_rate_Hz);
  kp_ = k.kp;
  ki_s_ = k.ki;
  kd_s_ = k.kd;
  if (!(sample_rate_Hz > 0.0) || !std::isfinite(sample_rate_Hz))
    throw InputError(fmt::format("PID sample rate {} Hz: must be > 0", sample_rate_Hz));
  if (!(g.reference_rate_Hz > 0.0) || !std::isfinite(g.reference_rate_Hz))
    throw InputError(
        fmt::format("PID gain reference rate {} Hz: must be > 0", g.reference_rate_Hz));
  if (!(u_max >= u_min)) throw InputError("PID output limits: the maximum is below the minimum");
}

void Pid::reset() {
  sum_ = 0.0;
  e_prev_ = 0.0;
  first_ = true;
}

double Pid::update(double e) {
  const double de = first_ ? 0.0 : e - e_prev_;  // no derivative kick on the first sample
  first_ = false;
  e_prev_ = e;
  const double sum_new = sum_ + e;
  const double u_raw = kp_ * e + ki_s_ * sum_new + kd_s_ * de;
  double u = u_raw;
  if (u_raw > u_max_) u = u_max_;
  if (u_raw < u_min_) u = u_min_;
  // Conditional integration: while clipped, do not let the sum grow further into the limit.
  const bool winding_up = (u_raw > u_max_ && e > 0.0) || (u_raw < u_min_ && e < 0.0);
  if (!winding_up) sum_ = sum_new;
  return u;
}

void Pid::set_limits(double u_min, double u_max) {
  u_min_ = u_min;
  u_max_ = u_max;
}

double TemperatureFeedforward::gain_at(double T) const {
  return gains.empty() ? 1.0 : interpolate_held(temperatures_C, gains, T);
}

// ---------------------------------------------------------------------------------------
// The experiment
// ---------------------------------------------------------------------------------------
namespace {

void check_feedforward(const TemperatureFeedforward& ff) {
  if (!ff.enabled()) return;
  if (ff.gains.size() != ff.temperatures_C.size())
    throw InputError(fmt::format("temperature feed-forward: {} gains for {} temperatures",
                                 ff.gains.size(), ff.temperatures_C.size()));
  if (static_cast<double>(ff.gains.size()) > kMaxListValues)
    throw InputError(fmt::format("temperature feed-forward: {} points (limit {:g})",
                                 ff.gains.size(), kMaxListValues));
  for (std::size_t k = 0; k < ff.gains.size(); ++k) {
    require_finite(ff.temperatures_C[k], "feed-forward temperature", "degC");
    require_in(ff.gains[k], 1e-3, 1e3, "feed-forward gain");
    if (k > 0 && !(ff.temperatures_C[k] > ff.temperatures_C[k - 1]))
      throw InputError(fmt::format(
          "temperature feed-forward: temperatures must increase ({} degC after {} degC)",
          ff.temperatures_C[k], ff.temperatures_C[k - 1]));
  }
  require_in(ff.static_gain_um_per_A, 0.0, 1e6, "feed-forward static gain", "um/A");
}

void check_positive_list(const std::vector<double>& v, const char* what, const char* unit) {
  if (v.empty()) throw InputError(fmt::format("track: no {} given: give at least one", what));
  for (double x : v)
    if (!(x > 0.0) || !std::isfinite(x))
      throw InputError(fmt::format("{} = {} {}: must be > 0", what, x, unit));
  if (static_cast<double>(v.size()) > kMaxListValues)
    throw InputError(
        fmt::format("{} {} values: too many (limit {:g})", v.size(), what, kMaxListValues));
}

}  // namespace

void detail::check_track_request(const TrackRequest& r) {
  if (r.temperatures_C.empty())
    throw InputError("track: no temperature given (--temperatures): give at least one");
  for (double T : r.temperatures_C) require_finite(T, "temperature (--temperatures)", "degC");
  check_positive_list(r.amplitudes_um, "reference amplitude (--amplitudes)", "um");
  check_positive_list(r.frequencies_Hz, "reference frequency (--frequencies)", "Hz");
  // A reference beyond 10 mm is no actuator's stroke: refuse it rather than report a
  // saturated loop with astronomically large errors.
  for (double A : r.amplitudes_um)
    require_in(A, 0.0, kMaxTrackAmplitude_um, "reference amplitude (--amplitudes)", "um");
  for (double f : r.frequencies_Hz)
    require_in(f, 0.0, kMaxFrequency_Hz, "reference frequency (--frequencies)", "Hz");
  require_in(r.sample_rate_Hz, 0.0, 1e3 * kMaxFrequency_Hz, "PID sample rate (--sample-rate)",
             "Hz");
  require_in(r.bias_A, -kMaxCurrent_A, kMaxCurrent_A, "bias current (--bias)", "A");
  require_in(r.current_limit_A, 0.0, kMaxCurrent_A, "current limit (--current-limit)", "A");
  for (double g : {r.gains.kp, r.gains.ki, r.gains.kd})
    require_finite(g, "PID gain (--kp, --ki, --kd)");
  require_in(r.amplifier_A_per_unit, 1e-6, 1e6, "amplifier gain (--amplifier-gain)", "A per unit");
  // The gains are per sample at this rate (Pid): a rate of 4.9e-324 Hz would scale kd by
  // 1e300+ (found by the mutation campaign).
  require_in(r.gains.reference_rate_Hz, 1e-3, 1e9, "PID gain reference rate (--gain-rate)", "Hz");
  require_in(r.sensor_noise_um, 0.0, kMaxTrackAmplitude_um, "sensor noise (--sensor-noise)", "um");
  require_in(r.periods, 1.0, kMaxPeriods, "periods (--periods)");
  const double runs = static_cast<double>(r.temperatures_C.size()) *
                      static_cast<double>(r.amplitudes_um.size()) *
                      static_cast<double>(r.frequencies_Hz.size());
  if (runs > kMaxGridRuns)
    throw InputError(
        fmt::format("track grid of {:.4g} runs: too many (limit {:g})", runs, kMaxGridRuns));
  if (!(r.sample_rate_Hz > 0.0) || !std::isfinite(r.sample_rate_Hz))
    throw InputError(
        fmt::format("PID sample rate (--sample-rate) = {} Hz: must be > 0", r.sample_rate_Hz));
  for (double f : r.frequencies_Hz)
    if (r.sample_rate_Hz < 2.0 * f)
      throw InputError(fmt::format(
          "PID sample rate (--sample-rate) = {} Hz is below twice the reference frequency {} Hz "
          "(Nyquist): the "
          "controller cannot see the reference; raise --sample-rate to at least {} Hz",
          r.sample_rate_Hz, f, 2.0 * f));
  if (!(r.current_limit_A > 0.0) || !std::isfinite(r.current_limit_A))
    throw InputError(
        fmt::format("current limit (--current-limit) = {} A: must be > 0", r.current_limit_A));
  if (!(std::fabs(r.bias_A) < r.current_limit_A))
    throw InputError(fmt::format(
        "bias current (--bias) = {} A: must lie inside the current limit (--current-limit) +-{} A",
        r.bias_A, r.current_limit_A));
  if (!(r.sensor_noise_um >= 0.0) || !std::isfinite(r.sensor_noise_um))
    throw InputError(
        fmt::format("sensor noise (--sensor-noise) = {} um: must be >= 0", r.sensor_noise_um));
  if (!(r.periods >= 1.0) || !std::isfinite(r.periods))
    throw InputError(fmt::format("periods {}: must be >= 1", r.periods));
  if (!(r.dt_s >= 0.0) || !std::isfinite(r.dt_s))
    throw InputError(fmt::format("dt = {} s (--dt): must be >= 0 (0: the automatic rule)", r.dt_s));
  check_feedforward(r.feedforward);
  if (r.controller && (r.inverse.enabled || r.feedforward.enabled()))
    throw InputError(
        "track: a user controller replaces the PID; it cannot be combined with the inverse or "
        "the temperature feed-forward (put them in the controller)");
  if (r.inverse.enabled && r.feedforward.enabled())
    throw InputError(
        "track: the inverse and the temperature feed-forward cannot be combined: choose one");
  require_in(r.inverse.band_Hz, 0.0, 1e5, "feed-forward band (--feedforward-band)", "Hz");
  Pid probe(r.gains, r.sample_rate_Hz, -1.0, 1.0);  // validates the gains' reference rate
  (void)probe;
  fields::check_request_fields(r);  // the table's rules (gmasim/experiments/experiment_fields.hpp)
}

// The plant steps per controller sample: dt divides the sample period, dt <= 10 us and
// dt <= T_ref/2000 (docs/model.md rule). Every run's length is checked here, before any run.
long detail::track_substeps(const TrackRequest& r) {
  const double Ts = 1.0 / r.sample_rate_Hz;
  double f_max = 0.0;
  for (double f : r.frequencies_Hz) f_max = std::max(f_max, f);
  // A given dt must fit in a PID sample (a longer one became the sample period silently)
  if (r.dt_s > 0.0 && !(r.dt_s <= Ts * (1.0 + 1e-12)))
    throw InputError(fmt::format(
        "dt = {:g} s (--dt): longer than the PID sample period 1 / --sample-rate = {:g} s; give "
        "dt <= {:g} s, or 0 for the automatic rule",
        r.dt_s, Ts, Ts));
  const double dt_target =
      r.dt_s > 0.0 ? r.dt_s : std::min(kMaxDt_s, 1.0 / (kStepsPerPeriod * f_max));
  const long sub = steps_to_resolve(Ts / dt_target, 1, "plant steps per PID sample");
  double f_min = f_max;
  for (double f : r.frequencies_Hz) f_min = std::min(f_min, f);
  (void)StepGrid::sampled(0.0, Ts, r.periods / f_min / Ts, sub, "plant steps of the longest run");
  // The example run's log (track_example.csv) holds a row per PID sample: bounded like a recorded
  // series (--sample-rate 1e9 grew it to GBs before the run ended).
  const double samples = r.periods / f_min / Ts;
  if (samples > kMaxRecordedRows)
    throw InputError(fmt::format(
        "track: {:.4g} PID samples in the longest run ({:g} periods at {:g} Hz, --sample-rate {:g} "
        "Hz) are logged for the example (limit {:g} rows); lower --sample-rate or --periods",
        samples, r.periods, f_min, r.sample_rate_Hz, kMaxRecordedRows));
  return sub;
}

namespace {

// The reference y_bias + A sin(w t) [um].
struct Reference {
  double y_bias_um, A_um, w_rad_per_s;
  double at(double t) const { return y_bias_um + A_um * std::sin(w_rad_per_s * t); }
  // The deviation from y_bias and its first three time derivatives at t [um/s^n].
  std::array<double, 4> derivatives(double t) const {
    const double w = w_rad_per_s, s = A_um * std::sin(w * t), c = A_um * std::cos(w * t);
    return {s, w * c, -w * w * s, -w * w * w * c};
  }
};

// The controller as the run loop's drive: at the first plant step of each sample it reads the
// sensor (y at the sample time t_k, + white noise) and computes the current, held until
// t_k+1. With the temperature feed-forward, i = bias + g (u + r'/K_ref). Logs each sample to
// `example` if given.
struct SampledController {
  const TrackRequest& r;
  const StepGrid& grid;
  const Reference& ref;
  Pid pid;
  double g;
  std::mt19937_64 rng;
  TimeSeries* example;
  InverseFeedforward* inverse;
  double temperature_C;
  std::normal_distribution<double> noise{0.0, 1.0};
  double I = 0.0, ff_min = 0.0, ff_max = 0.0;
  // The sampled error's sign changes over the last period (from after_s): a loop that rings at
  // the sampling's Nyquist frequency flips it every sample (TrackPoint::error_alternation).
  double after_s = std::numeric_limits<double>::infinity(), e_last = 0.0;
  long pairs = -1, flips = 0;

  void count_sign(double tk, double e) {
    if (!(tk > after_s)) return;
    if (pairs >= 0 && e * e_last < 0.0) ++flips;
    ++pairs;
    e_last = e;
  }

  // The user controller's current, clipped by the amplifier.
  double user_current(double tk, double y_meas) {
    const double i = r.controller(ref.at(tk), y_meas, temperature_C);
    if (!std::isfinite(i))
      throw InputError(fmt::format(
          "track: the controller returned {} A at sample {} (t = {:g} s, {:g} degC): a current "
          "must be a finite number",
          i, std::lround(tk / grid.sample_s), tk, temperature_C));
    return std::clamp(i, -r.current_limit_A, r.current_limit_A);
  }

  // With the inverse feed-forward: i = clip(i_ff + a u); the PID's limits follow i_ff.
  double with_inverse(double tk, double e) {
    const double lim = r.current_limit_A, a = r.amplifier_A_per_unit;
    const double i_ff = inverse->current_A(ref.derivatives(tk + 0.5 * grid.sample_s));
    ff_min = tk == 0.0 ? i_ff : std::min(ff_min, i_ff);
    ff_max = tk == 0.0 ? i_ff : std::max(ff_max, i_ff);
    pid.set_limits((-lim - i_ff) / a, (lim - i_ff) / a);
    return std::clamp(i_ff + a * pid.update(e), -lim, lim);
  }

  double operator()(const State& s, const StepPoint& p) {
    if (p.substep != 1) return I;
    const double tk = grid.sample_time(p.sample);
    const double y_meas =
        s.y_m * 1e6 + r.sensor_noise_um * (r.sensor_noise_um > 0.0 ? noise(rng) : 0.0);
    count_sign(tk, ref.at(tk) - y_meas);
    if (r.controller) {
      I = user_current(tk, y_meas);
      log(s, tk);
      return I;
    }
    if (inverse != nullptr) {
      I = with_inverse(tk, ref.at(tk) - y_meas);
      log(s, tk);
      return I;
    }
    const double u = pid.update(ref.at(tk) - y_meas);
    const double K_ref = r.feedforward.static_gain_um_per_A;
    const double ff = K_ref > 0.0 ? (ref.at(tk) - ref.y_bias_um) / K_ref : 0.0;
    const double a = r.amplifier_A_per_unit;
    I = r.feedforward.enabled()
            ? std::clamp(r.bias_A + g * (a * u + ff), -r.current_limit_A, r.current_limit_A)
            : r.bias_A + a * u;
    log(s, tk);
    return I;
  }

  void log(const State& s, double tk) {
    if (!example) return;
    auto& col = example->columns;
    col[0].push_back(tk);
    col[1].push_back(ref.at(tk));
    col[2].push_back(s.y_m * 1e6);
    col[3].push_back(I);
    col[4].push_back(ref.at(tk) - s.y_m * 1e6);
  }
};

// The tracking error and the current over (t_end - T, t_end]: one whole period.
struct ErrorOverLastPeriod {
  const Reference& ref;
  double after_s;
  double ss = 0.0, peak = 0.0, Imin = 1e300, Imax = -1e300;
  long n = 0;

  void operator()(const State& s, const StepPoint& p) {
    if (!(p.t_s > after_s)) return;
    const double e = ref.at(p.t_s) - s.y_m * 1e6;
    ss += e * e;
    peak = std::max(peak, std::fabs(e));
    ++n;
    Imin = std::min(Imin, s.current_A);
    Imax = std::max(Imax, s.current_A);
  }
};

}  // namespace

void detail::track_run(const TrackPlant& plant, const TrackRequest& r, const TrackJob& j, long sub,
                       std::uint64_t seed, TrackPoint& p, TimeSeries* example) {
  const Model& m = plant.model;
  const Conditions& c = plant.conditions;
  p.temperature_C = j.T;
  p.amplitude_um = j.A;
  p.frequency_Hz = j.f;
  const double Ts = 1.0 / r.sample_rate_Hz;
  const double period = 1.0 / j.f;
  const StepGrid grid = StepGrid::sampled(
      0.0, Ts, static_cast<double>(std::lround(r.periods * period / Ts)), sub, "plant steps");
  const double t_end = static_cast<double>(grid.samples()) * Ts;
  // The PID's own limits are those of u = (i - bias) / (g a), so its anti-windup acts where the
  // current clips.
  const double g = r.feedforward.gain_at(j.T);
  const double ga = g * r.amplifier_A_per_unit;
  p.feedforward_gain = g;
  try {
    State s = make_state(m, c, r.bias_A);
    p.y_bias_um = s.y_m * 1e6;
    const Reference ref{p.y_bias_um, j.A, 2.0 * physics::kPi * j.f};
    SampledController drive{r,
                            grid,
                            ref,
                            Pid(r.gains, r.sample_rate_Hz, (-r.current_limit_A - r.bias_A) / ga,
                                (r.current_limit_A - r.bias_A) / ga),
                            g,
                            std::mt19937_64(seed),
                            example,
                            plant.inverse,
                            j.T};
    if (r.controller_reset) r.controller_reset();
    if (plant.inverse != nullptr) plant.inverse->reset();
    ErrorOverLastPeriod err{ref, (t_end - period) + 1e-12 * period};
    drive.after_s = err.after_s;
    run_loop(m, c, s, grid, drive, err);
    if (drive.pairs > 0) {
      p.error_alternation = static_cast<double>(drive.flips) / static_cast<double>(drive.pairs);
      p.error_oscillation_Hz = 0.5 * p.error_alternation * r.sample_rate_Hz;
      p.limit_cycle = p.error_alternation > kLimitCycleAlternation;
    }
    p.error_rms_um = std::sqrt(err.ss / static_cast<double>(std::max(err.n, 1L)));
    p.error_peak_um = err.peak;
    p.error_rms_pct = p.error_rms_um / j.A * 100.0;
    p.current_min_A = err.Imin;
    p.current_max_A = err.Imax;
    p.saturated = err.Imax >= r.current_limit_A - 1e-12 || err.Imin <= -r.current_limit_A + 1e-12;
    p.feedforward_min_A = drive.ff_min;
    p.feedforward_max_A = drive.ff_max;
  } catch (const DivergenceError& e) {
    p.diverged = true;
    p.error = e.what();
    p.error_rms_um = p.error_peak_um = p.error_rms_pct = std::nan("");
  }
}

TrackResult run_track(const Model& m, const TrackRequest& r, const ProgressFn& progress) {
  detail::check_track_request(r);
  std::vector<Conditions> conds;
  for (double T : r.temperatures_C) conds.push_back(make_conditions(m, T));
  const InverseFeedforwardSettings inv{r.bias_A, r.current_limit_A, r.sample_rate_Hz,
                                       r.inverse.band_Hz, r.inverse.dynamic};
  std::vector<LinearInverse> linear;  // one fit per temperature
  if (r.inverse.enabled)
    for (const auto& c : conds) linear.push_back(fit_linear_inverse(m, c, r.bias_A, inv.band_Hz));

  std::vector<detail::TrackJob> jobs;
  for (double T : r.temperatures_C)
    for (double A : r.amplitudes_um)
      for (double f : r.frequencies_Hz) jobs.push_back({T, A, f});
  const std::size_t per_T = r.amplitudes_um.size() * r.frequencies_Hz.size();
  const long sub = detail::track_substeps(r);

  TrackResult res;
  res.plant_dt_s = 1.0 / r.sample_rate_Hz / static_cast<double>(sub);
  res.threads = r.controller ? 1 : resolve_thread_count(r.threads, jobs.size());
  res.points.resize(jobs.size());
  const auto wall0 = std::chrono::steady_clock::now();
  detail::parallel_for(
      jobs.size(), res.threads,
      [&](std::size_t idx) {
        TimeSeries ex;  // the first point's run, sample by sample
        if (idx == 0) {
          ex.names = {"t_s", "reference_um", "y_um", "current_A", "error_um"};
          ex.columns.assign(ex.names.size(), {});
        }
        std::optional<InverseFeedforward> ff;
        if (r.inverse.enabled) ff.emplace(m, jobs[idx].T, inv, &linear[idx / per_T]);
        const detail::TrackPlant plant{m, conds[idx / per_T], ff ? &*ff : nullptr};
        detail::track_run(plant, r, jobs[idx], sub, r.noise_seed + idx, res.points[idx],
                          idx == 0 ? &ex : nullptr);
        if (idx == 0) res.example = std::move(ex);
      },
      progress);
  for (std::size_t t = 0; t < conds.size() && !r.controller; ++t)  // the PID's, per temperature
    res.margins.push_back(pid_loop_margins(
        linearize_plant(m, conds[t], r.bias_A), r.gains, r.sample_rate_Hz, res.plant_dt_s,
        r.amplifier_A_per_unit * r.feedforward.gain_at(r.temperatures_C[t])));
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  for (std::size_t i = 0; i < res.points.size(); ++i)
    res.points[i].error_change_pct =
        detail::change_pct(res.points[i % per_T].error_rms_um, res.points[i].error_rms_um);
  return res;
}

}  // namespace gmasim
