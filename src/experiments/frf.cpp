// gmasim frf (Fig. 15): frequency response current -> displacement about a DC bias, by a
// stepped sine (time-domain runs of step()) beside the small-signal linearisation and the
// modes of eq. (15) of the mechanics module (gmasim/mechanics/mechanics.hpp,
// src/mechanics/). docs/experiments.md, "Frequency response".
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>

#include "experiments/frf_internal.hpp"
#include "experiments/parallel.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/claims.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/frf_bias.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/simulate/run_loop.hpp"

namespace gmasim {
namespace {

using namespace physics;
using cd = std::complex<double>;

double unwrap_deg(double prev, double now) {
  while (now - prev > 180.0) now -= 360.0;
  while (now - prev < -180.0) now += 360.0;
  return now;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Measurement helpers
// ---------------------------------------------------------------------------------------
std::complex<double> first_harmonic_ratio(const std::vector<double>& t_s,
                                          const std::vector<double>& y,
                                          const std::vector<double>& i, double f_Hz) {
  detail::FirstHarmonicSums sums;
  for (std::size_t k = 0; k < t_s.size(); ++k) sums.add(t_s[k], f_Hz, y[k], i[k]);
  return sums.ratio();
}

// ---------------------------------------------------------------------------------------
// The experiment
// ---------------------------------------------------------------------------------------
namespace {

void check_request(const FrfRequest& r) {
  if (r.temperatures_C.empty())
    throw InputError("frf: no temperature given (--temperatures): give at least one");
  if (!(r.f_min_Hz > 0.0) || !std::isfinite(r.f_min_Hz))
    throw InputError(fmt::format("lowest frequency (--f-min) = {} Hz: must be > 0", r.f_min_Hz));
  if (!(r.f_max_Hz > r.f_min_Hz) || !std::isfinite(r.f_max_Hz))
    throw InputError(fmt::format(
        "frequency range (--f-min .. --f-max) {} .. {} Hz: the maximum must exceed the minimum",
        r.f_min_Hz, r.f_max_Hz));
  if (r.points < 2)
    throw InputError(fmt::format("points (--points) = {}: need at least 2", r.points));
  if (!(r.amplitude_A > 0.0) || !std::isfinite(r.amplitude_A))
    throw InputError(fmt::format("amplitude (--amplitude) = {} A: must be > 0", r.amplitude_A));
  if (!std::isfinite(r.bias_A)) throw InputError("bias current (--bias): not a finite number");
  if (r.min_steps_per_period < 20)
    throw InputError(fmt::format("steps per period {}: need at least 20", r.min_steps_per_period));
  if (r.settle_periods < 1 || r.measure_periods < 1)
    throw InputError(
        fmt::format("settle periods (--settle-periods) {} / measure periods (--measure-periods) "
                    "{}: must be >= 1",
                    r.settle_periods, r.measure_periods));
  if (!r.stepped_sine && !r.small_signal)
    throw InputError("frf: neither the stepped sine nor the small-signal method is selected");
  for (double T : r.temperatures_C) require_finite(T, "temperature (--temperatures)", "degC");
  if (static_cast<double>(r.temperatures_C.size()) > kMaxListValues)
    throw InputError(fmt::format("frf: {} temperatures: too many (limit {:g})",
                                 r.temperatures_C.size(), kMaxListValues));
  require_in(r.f_max_Hz, 0.0, kMaxFrequency_Hz, "maximum frequency (--f-max)", "Hz");
  (void)checked_count(r.points, kMaxFrfPoints, "frequency points (--points)");
  require_in(r.amplitude_A, 0.0, kMaxCurrent_A, "amplitude (--amplitude)", "A");
  require_in(r.bias_A, -kMaxCurrent_A, kMaxCurrent_A, "bias current (--bias)", "A");
  require_in(r.bias_A + r.amplitude_A, -kMaxCurrent_A, kMaxCurrent_A,
             "peak current (--bias + --amplitude)", "A");
  require_in(r.bias_A - r.amplitude_A, -kMaxCurrent_A, kMaxCurrent_A,
             "lowest current (--bias - --amplitude)", "A");
  require_int_in(r.settle_periods, 1, 1000000, "settle periods");
  require_int_in(r.measure_periods, 1, 1000000, "measure periods");
  // Golden section shrinks its bracket by 0.618 per evaluation: 100 reach 1e-21 of it, far below
  // what a double resolves, so more is a typing error that would run for hours.
  require_int_in(r.peak_refinements, 0, 100, "peak refinements (--peak-refinements)");
  if (r.stepped_sine) {
    // The longest stepped-sine run (at f_min) before settling for the model's time
    // constants; the settling is checked again per frequency once those are known.
    const double per = std::max(static_cast<double>(r.min_steps_per_period),
                                std::ceil(1.0 / (r.f_min_Hz * kMaxDt_s) - 1e-9));
    (void)StepGrid::uniform(0.0, 1.0 / (r.f_min_Hz * per),
                            per * (r.settle_periods + r.measure_periods),
                            fmt::format("stepped-sine steps at {:g} Hz", r.f_min_Hz));
  }
}

// The transient of switching the sine on decays with the slowest of the eddy lags and the
// mechanical modes: 10 of those time constants (the transient is then below 5e-5 of its start).
double settling_time_s(const SmallSignalModel& lin) {
  double t_settle = 0.0;
  for (std::size_t i = 0; i < lin.tau_s.size(); ++i) {
    const double zw = lin.damping_N_s_per_m[i] / (2.0 * lin.mass_kg[i]);
    t_settle = std::max({t_settle, 10.0 * lin.tau_s[i], 10.0 / zw});
  }
  if (lin.sensor_mount && lin.sm_damping_N_s_per_m > 0)
    t_settle = std::max(t_settle, 10.0 * 2.0 * lin.sm_mass_kg / lin.sm_damping_N_s_per_m);
  return t_settle;
}

}  // namespace

// One stepped-sine point: the sine switched on at the bias state, >= min_steps_per_period
// steps per period with dt <= 10 us (whole steps per period); settled for settling_time_s and
// at least settle_periods periods (low frequencies need few periods, high frequencies many),
// then the first harmonic of y over measure_periods whole periods.
detail::SteppedSineGrid detail::stepped_sine_grid(const SmallSignalModel& lin, const FrfRequest& r,
                                                  double fr) {
  const long per =
      steps_to_resolve(1.0 / (fr * kMaxDt_s), r.min_steps_per_period, "steps per period");
  const double dt = 1.0 / (fr * static_cast<double>(per));
  const long settle =
      steps_to_resolve(settling_time_s(lin) * fr, r.settle_periods, "settle periods");
  const long measure = r.measure_periods;
  SteppedSineGrid sg;
  sg.grid =
      StepGrid::uniform(0.0, dt, static_cast<double>(settle + measure) * static_cast<double>(per),
                        fmt::format("stepped-sine steps at {:g} Hz", fr));
  sg.first = settle * per;
  sg.measured = measure * per;
  return sg;
}

cd detail::stepped_sine_point(const Model& m, const Conditions& c, const State& bias,
                              const SmallSignalModel& lin, const FrfRequest& r, double fr) {
  const SteppedSineGrid sg = stepped_sine_grid(lin, r, fr);
  std::vector<double> ts, ys, is;
  ts.reserve(static_cast<std::size_t>(sg.measured));
  ys.reserve(ts.capacity());
  is.reserve(ts.capacity());
  const long first = sg.first;  // samples first+1 .. total: whole periods
  State s = bias;
  try {
    run_loop(
        m, c, s, sg.grid, [&](double t) { return stepped_sine_current_A(r, fr, t); },
        [&](const State& st, const StepPoint& p) {
          if (p.k <= first) return;
          ts.push_back(p.t_s);
          ys.push_back(st.y_m - lin.y0_m);
          is.push_back(st.current_A - r.bias_A);
        });
  } catch (const DivergenceError& e) {  // the point's temperature and frequency, as the lanes
    throw DivergenceError(stepped_sine_divergence(r, c.temperature_C, fr, e.what()));
  }
  return first_harmonic_ratio(ts, ys, is, fr);
}

std::string detail::stepped_sine_divergence(const FrfRequest& r, double temperature_C, double f_Hz,
                                            const std::string& why) {
  return fmt::format(
      "frf: the stepped sine of +-{:g} A (--amplitude) about the {:g} A bias at {:g} degC, {:g} Hz "
      "diverged: {}; a smaller --amplitude stays nearer the bias (the small-signal default is "
      "1e-4 A)",
      r.amplitude_A, r.bias_A, temperature_C, f_Hz, why);
}

namespace {

// The bias point's curve: the bias output, the eddy lags, the modes, the static gain.
FrfCurve bias_curve(const Model& m, const Conditions& c, const State& bias,
                    const SmallSignalModel& lin, double T, const std::vector<double>& f) {
  FrfCurve cv;
  cv.temperature_C = T;
  cv.f_Hz = f;
  cv.y_bias_um = bias.y_m * 1e6;
  for (const auto& rd : bias.rods) cv.eddy_tau_ms.push_back(rd.tau_s * 1e3);
  for (const Mode& md : mechanical_modes(m, c, bias)) {
    cv.mode_frequencies_Hz.push_back(md.frequency_Hz);
    cv.mode_damping_ratios.push_back(md.damping_ratio);
  }
  cv.static_gain_um_per_A = std::abs(lin.response(0.0)) * 1e6;
  return cv;
}

// Magnitudes and unwrapped phases of both methods, their mismatch, resonance and bandwidth.
void fill_curve(FrfCurve& cv, const SmallSignalModel& lin, const cd* stepped,
                const std::vector<double>& f, const FrfRequest& r) {
  cv.f_Hz = f;
  double prev_l = 0.0, prev_s = 0.0;
  for (std::size_t fi = 0; fi < f.size(); ++fi) {
    if (r.small_signal) {
      const cd Y = lin.response(f[fi]);
      cv.linear_mag_um_per_A.push_back(std::abs(Y) * 1e6);
      const double ph = std::arg(Y) * 180.0 / kPi;
      prev_l = fi == 0 ? ph : unwrap_deg(prev_l, ph);
      cv.linear_phase_deg.push_back(prev_l);
    }
    if (r.stepped_sine) {
      const cd Y = stepped[fi];
      cv.stepped_mag_um_per_A.push_back(std::abs(Y) * 1e6);
      const double ph = std::arg(Y) * 180.0 / kPi;
      prev_s = fi == 0 ? ph : unwrap_deg(prev_s, ph);
      cv.stepped_phase_deg.push_back(prev_s);
    }
    if (r.small_signal && r.stepped_sine) {
      const cd d = stepped[fi] - lin.response(f[fi]);
      cv.max_mismatch_pct =
          std::max(cv.max_mismatch_pct, std::abs(d) / std::abs(lin.response(f[fi])) * 100.0);
    }
  }
  if (r.stepped_sine) {
    cv.stepped_first_resonance_Hz = detail::data_peak(f, cv.stepped_mag_um_per_A).f_Hz;
    cv.stepped_bandwidth_3dB_Hz = find_bandwidth_3dB_Hz(f, cv.stepped_mag_um_per_A);
  }
  if (!r.small_signal) return;  // markers from the stepped sine (detail::choose_markers)
  // Resonance and bandwidth of the linear model on a dense grid (cheap to evaluate).
  const LinearFrfMarkers lm = linear_frf_markers(lin, r.f_min_Hz, r.f_max_Hz);
  cv.first_resonance_Hz = lm.first_resonance_Hz;
  if (cv.first_resonance_Hz > 0)
    cv.first_resonance_mag_um_per_A = std::abs(lin.response(cv.first_resonance_Hz)) * 1e6;
  cv.bandwidth_3dB_Hz = lm.bandwidth_3dB_Hz;
  // The same search beyond the band, up to twice the highest mode.
  double f_top = r.f_max_Hz;
  for (double fm : cv.mode_frequencies_Hz) f_top = std::max(f_top, 2.0 * fm);
  const std::vector<double> fe = detail::log_grid(r.f_min_Hz, f_top, 8000);
  std::vector<double> me(fe.size());
  for (std::size_t k = 0; k < fe.size(); ++k) me[k] = std::abs(lin.response(fe[k]));
  cv.linear_peak_extended_Hz = find_resonance_Hz(fe, me);
  cv.linear_peak_search_max_Hz = f_top;
}

}  // namespace

LinearFrfMarkers linear_frf_markers_at(const Model& m, const Conditions& c, const State& settled) {
  const FrfRequest r;
  return linear_frf_markers(linearise(m, c, settled), r.f_min_Hz, r.f_max_Hz);
}

LinearFrfMarkers linear_frf_markers(const Model& m, double T_C, double bias_A) {
  const Conditions c = make_conditions(m, T_C);
  return linear_frf_markers_at(m, c, settle_at_bias(m, c, bias_A, FrfRequest{}.bias_state));
}

FrfResult run_frf(const Model& m, const FrfRequest& r, const ProgressFn& progress) {
  check_request(r);
  fields::check_request_fields(r);  // the table's rules (gmasim/experiments/experiment_fields.hpp)
  std::vector<Conditions> conds;
  for (double T : r.temperatures_C) conds.push_back(make_conditions(m, T));

  const auto wall0 = std::chrono::steady_clock::now();
  const std::vector<double> f = detail::log_grid(r.f_min_Hz, r.f_max_Hz, r.points);
  const std::size_t nT = r.temperatures_C.size(), nf = f.size();

  // Bias points, linearisations and modes (cheap; one per temperature).
  std::vector<State> bias;
  std::vector<SmallSignalModel> lin;
  FrfResult res;
  res.paper_first_resonance_Hz = builtin_paper_value("first_resonance");
  res.paper_bandwidth_Hz = builtin_paper_value("bandwidth");
  for (std::size_t ti = 0; ti < nT; ++ti) {
    bias.push_back(settle_at_bias(m, conds[ti], r.bias_A, r.bias_state));
    lin.push_back(linearise(m, conds[ti], bias.back()));
    res.curves.push_back(
        bias_curve(m, conds[ti], bias.back(), lin.back(), r.temperatures_C[ti], f));
  }

  // Stepped sine: one work item per (temperature, frequency).
  std::vector<cd> stepped(nT * nf);
  if (r.stepped_sine && r.lanes &&
      lanes_supported(m)) {  // the points in SIMD lanes (frf_lanes.cpp)
    stepped = detail::stepped_sine_points_lanes(m, conds, bias, lin, r, f,
                                                resolve_thread_count(r.threads, nT * nf), progress);
  } else if (r.stepped_sine) {
    const std::size_t n = nT * nf;
    detail::parallel_for(
        n, resolve_thread_count(r.threads, n),
        [&](std::size_t idx) {
          const std::size_t ti = idx / nf, fi = idx % nf;
          stepped[idx] = detail::stepped_sine_point(m, conds[ti], bias[ti], lin[ti], r, f[fi]);
        },
        progress);
  } else if (progress) {
    progress(nT, nT);
  }
  // The stepped sine's peak refined per temperature (golden section in ln f, frf_peak.cpp).
  std::vector<detail::SteppedCurve> sc(nT);
  for (std::size_t ti = 0; ti < nT; ++ti) {
    sc[ti].f_Hz = f;
    sc[ti].Y.assign(stepped.begin() + static_cast<std::ptrdiff_t>(ti * nf),
                    stepped.begin() + static_cast<std::ptrdiff_t>((ti + 1) * nf));
  }
  if (r.stepped_sine && r.peak_refinements > 0)
    detail::parallel_for(nT, resolve_thread_count(r.threads, nT),
                         [&](std::size_t ti) {
                           detail::refine_stepped_peak(m, conds[ti], bias[ti], lin[ti], r, sc[ti]);
                         },
                         {});
  for (std::size_t ti = 0; ti < nT; ++ti) {
    fill_curve(res.curves[ti], lin[ti], sc[ti].Y.data(), sc[ti].f_Hz, r);
    detail::choose_markers(res.curves[ti], m, lin[ti], conds[ti], r);
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  for (auto& cv : res.curves) cv.wall_time_s = wall;
  return res;
}

}  // namespace gmasim
