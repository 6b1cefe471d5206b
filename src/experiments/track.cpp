// gmasim track (Fig. 16): closed-loop displacement tracking with the paper's PID, a
// discrete controller with a sampled displacement sensor driving the coil current.
// docs/experiments.md, "Closed-loop tracking".
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "experiments/parallel.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate.hpp"
#include "gmasim/validate.hpp"

namespace gmasim {

// ---------------------------------------------------------------------------------------
// PID
// ---------------------------------------------------------------------------------------
Pid::Pid(const PidGains& g, double sample_rate_Hz, double u_min, double u_max)
    : kp_(g.kp),
      ki_s_(g.ki * g.reference_rate_Hz / sample_rate_Hz),
      kd_s_(g.kd * sample_rate_Hz / g.reference_rate_Hz),
      u_min_(u_min),
      u_max_(u_max) {
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

struct Job {
  double T, A, f;
};

void check_positive_list(const std::vector<double>& v, const char* what, const char* unit) {
  if (v.empty()) throw InputError(fmt::format("track: no {} given", what));
  for (double x : v)
    if (!(x > 0.0) || !std::isfinite(x))
      throw InputError(fmt::format("{} {} {}: must be > 0", what, x, unit));
  if (static_cast<double>(v.size()) > kMaxListValues)
    throw InputError(
        fmt::format("{} {} values: too many (limit {:g})", v.size(), what, kMaxListValues));
}

}  // namespace

TrackResult run_track(const Model& m, const TrackRequest& r, const ProgressFn& progress) {
  if (r.temperatures_C.empty()) throw InputError("track: no temperature given");
  for (double T : r.temperatures_C) require_finite(T, "temperature", "degC");
  check_positive_list(r.amplitudes_um, "reference amplitude", "um");
  check_positive_list(r.frequencies_Hz, "reference frequency", "Hz");
  // A reference beyond 10 mm is no actuator's stroke: refuse it rather than report a
  // saturated loop with astronomically large errors.
  for (double A : r.amplitudes_um)
    require_in(A, 0.0, kMaxTrackAmplitude_um, "reference amplitude", "um");
  for (double f : r.frequencies_Hz)
    require_in(f, 0.0, kMaxFrequency_Hz, "reference frequency", "Hz");
  require_in(r.sample_rate_Hz, 0.0, 1e3 * kMaxFrequency_Hz, "PID sample rate", "Hz");
  require_in(r.bias_A, -kMaxCurrent_A, kMaxCurrent_A, "bias current", "A");
  require_in(r.current_limit_A, 0.0, kMaxCurrent_A, "current limit", "A");
  for (double g : {r.gains.kp, r.gains.ki, r.gains.kd}) require_finite(g, "PID gain");
  // The gains are per sample at this rate (Pid): a rate of 4.9e-324 Hz would scale kd by
  // 1e300+ (found by the mutation campaign).
  require_in(r.gains.reference_rate_Hz, 1e-3, 1e9, "PID gain reference rate", "Hz");
  require_in(r.sensor_noise_um, 0.0, kMaxTrackAmplitude_um, "sensor noise", "um");
  require_in(r.periods, 1.0, kMaxPeriods, "periods");
  const double runs = static_cast<double>(r.temperatures_C.size()) *
                      static_cast<double>(r.amplitudes_um.size()) *
                      static_cast<double>(r.frequencies_Hz.size());
  if (runs > kMaxGridRuns)
    throw InputError(
        fmt::format("track grid of {:.4g} runs: too many (limit {:g})", runs, kMaxGridRuns));
  if (!(r.sample_rate_Hz > 0.0) || !std::isfinite(r.sample_rate_Hz))
    throw InputError(fmt::format("PID sample rate {} Hz: must be > 0", r.sample_rate_Hz));
  for (double f : r.frequencies_Hz)
    if (r.sample_rate_Hz < 2.0 * f)
      throw InputError(fmt::format(
          "PID sample rate {} Hz is below twice the reference frequency {} Hz (Nyquist): the "
          "controller cannot see the reference; raise --sample-rate to at least {} Hz",
          r.sample_rate_Hz, f, 2.0 * f));
  if (!(r.current_limit_A > 0.0) || !std::isfinite(r.current_limit_A))
    throw InputError(fmt::format("current limit {} A: must be > 0", r.current_limit_A));
  if (!(std::fabs(r.bias_A) < r.current_limit_A))
    throw InputError(fmt::format("bias current {} A: must lie inside the current limit +-{} A",
                                 r.bias_A, r.current_limit_A));
  if (!(r.sensor_noise_um >= 0.0) || !std::isfinite(r.sensor_noise_um))
    throw InputError(fmt::format("sensor noise {} um: must be >= 0", r.sensor_noise_um));
  if (!(r.periods >= 1.0) || !std::isfinite(r.periods))
    throw InputError(fmt::format("periods {}: must be >= 1", r.periods));
  if (!(r.dt_s >= 0.0) || !std::isfinite(r.dt_s))
    throw InputError(fmt::format("dt {} s: must be > 0 (or 0 for the automatic rule)", r.dt_s));
  check_feedforward(r.feedforward);
  {
    Pid probe(r.gains, r.sample_rate_Hz, -1.0, 1.0);  // validates the gains' reference rate
    (void)probe;
  }
  std::vector<Conditions> conds;
  for (double T : r.temperatures_C) conds.push_back(make_conditions(m, T));

  std::vector<Job> jobs;
  for (double T : r.temperatures_C)
    for (double A : r.amplitudes_um)
      for (double f : r.frequencies_Hz) jobs.push_back({T, A, f});
  const std::size_t per_T = r.amplitudes_um.size() * r.frequencies_Hz.size();

  // Plant step: divides the sample period, <= 10 us and <= T_ref/2000 (docs/model.md rule).
  const double Ts = 1.0 / r.sample_rate_Hz;
  double f_max = 0.0;
  for (double f : r.frequencies_Hz) f_max = std::max(f_max, f);
  const double dt_target =
      r.dt_s > 0.0 ? r.dt_s : std::min(kMaxDt_s, 1.0 / (kStepsPerPeriod * f_max));
  const long sub =
      std::max(1L, checked_ceil_count(Ts / dt_target, kMaxSteps, "plant steps per PID sample"));
  const double dt = Ts / static_cast<double>(sub);
  // Every run's length: samples of the PID and plant steps, checked before any run.
  double f_min = f_max;
  for (double f : r.frequencies_Hz) f_min = std::min(f_min, f);
  const double samples_max = r.periods / f_min / Ts;
  (void)checked_count(samples_max, kMaxSteps, "PID samples of the longest run");
  (void)checked_count(samples_max * static_cast<double>(sub), kMaxSteps,
                      "plant steps of the longest run");

  TrackResult res;
  res.plant_dt_s = dt;
  res.threads = resolve_thread_count(r.threads, jobs.size());
  res.points.resize(jobs.size());
  const auto wall0 = std::chrono::steady_clock::now();
  detail::parallel_for(
      jobs.size(), res.threads,
      [&](std::size_t idx) {
        const Job& j = jobs[idx];
        const Conditions& c = conds[idx / per_T];
        TrackPoint& p = res.points[idx];
        p.temperature_C = j.T;
        p.amplitude_um = j.A;
        p.frequency_Hz = j.f;
        const double period = 1.0 / j.f;
        const long samples = std::lround(r.periods * period / Ts);
        const double t_end = static_cast<double>(samples) * Ts;
        const double t_window = t_end - period;  // errors over the last period
        std::mt19937_64 rng(r.noise_seed + idx);
        std::normal_distribution<double> noise(0.0, 1.0);
        // With the temperature feed-forward, i = bias + g (u + r'/K_ref): the PID's own limits
        // are those of u = (i - bias) / g, so its anti-windup acts where the current clips.
        const double g = r.feedforward.gain_at(j.T);
        const double K_ref = r.feedforward.static_gain_um_per_A;
        p.feedforward_gain = g;
        Pid pid(r.gains, r.sample_rate_Hz, (-r.current_limit_A - r.bias_A) / g,
                (r.current_limit_A - r.bias_A) / g);
        const bool record = idx == 0;
        TimeSeries ex;
        if (record) {
          ex.names = {"t_s", "reference_um", "y_um", "current_A", "error_um"};
          ex.columns.assign(ex.names.size(), {});
        }
        double ss = 0.0, peak = 0.0, Imin = 1e300, Imax = -1e300;
        long n_err = 0;
        try {
          State s = make_state(m, c, r.bias_A);
          const double y_bias_um = s.y_m * 1e6;
          p.y_bias_um = y_bias_um;
          const double w = 2.0 * physics::kPi * j.f;
          auto ref = [&](double t) { return y_bias_um + j.A * std::sin(w * t); };
          double I = r.bias_A;
          for (long k = 0; k < samples; ++k) {
            const double tk = static_cast<double>(k) * Ts;
            // Sensor: y sampled at t_k (+ white noise); controller output held until t_k+1.
            const double y_meas =
                s.y_m * 1e6 + r.sensor_noise_um * (r.sensor_noise_um > 0.0 ? noise(rng) : 0.0);
            const double u = pid.update(ref(tk) - y_meas);
            const double ff = K_ref > 0.0 ? (ref(tk) - y_bias_um) / K_ref : 0.0;
            I = r.feedforward.enabled()
                    ? std::clamp(r.bias_A + g * (u + ff), -r.current_limit_A, r.current_limit_A)
                    : r.bias_A + u;
            if (record) {
              ex.columns[0].push_back(tk);
              ex.columns[1].push_back(ref(tk));
              ex.columns[2].push_back(s.y_m * 1e6);
              ex.columns[3].push_back(I);
              ex.columns[4].push_back(ref(tk) - s.y_m * 1e6);
            }
            for (long q = 1; q <= sub; ++q) {
              const double t = tk + static_cast<double>(q) * dt;
              step(m, c, s, {I, dt});
              s.t_s = t;
              if (t > t_window + 1e-12 * period) {  // (t_end - T, t_end]: one whole period
                const double e = ref(t) - s.y_m * 1e6;
                ss += e * e;
                peak = std::max(peak, std::fabs(e));
                ++n_err;
                Imin = std::min(Imin, I);
                Imax = std::max(Imax, I);
              }
            }
          }
          p.error_rms_um = std::sqrt(ss / static_cast<double>(std::max(n_err, 1L)));
          p.error_peak_um = peak;
          p.error_rms_pct = p.error_rms_um / j.A * 100.0;
          p.current_min_A = Imin;
          p.current_max_A = Imax;
          p.saturated = Imax >= r.current_limit_A - 1e-12 || Imin <= -r.current_limit_A + 1e-12;
        } catch (const DivergenceError& e) {
          p.diverged = true;
          p.error = e.what();
          p.error_rms_um = p.error_peak_um = p.error_rms_pct = std::nan("");
        }
        if (record) res.example = std::move(ex);
      },
      progress);
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  for (std::size_t i = 0; i < res.points.size(); ++i)
    res.points[i].error_change_pct =
        detail::change_pct(res.points[i % per_T].error_rms_um, res.points[i].error_rms_um);
  return res;
}

}  // namespace gmasim
