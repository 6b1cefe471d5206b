// gmasim compensate: the drive that restores a target stroke at each temperature (a root of
// stroke(drive) - target, bracketed and solved with Boost.Math's TOMS 748), the gain
// schedule those drives define, and tracking with the schedule as temperature feed-forward.
// docs/experiments.md, "Temperature compensation".
#include "gmasim/experiments/compensate.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <boost/math/tools/roots.hpp>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <utility>

#include "experiments/lockstep.hpp"
#include "experiments/parallel.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/model/self_heating.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "request_meta.hpp"

namespace gmasim {
namespace {

// The biased sine of drive x: x = pp (Amplitude) or x = g (Scale).
Waveform drive(const CompensateRequest& r, double x) {
  if (r.adjust == CompensationAdjust::Amplitude)
    return biased_sine(x, r.frequency_Hz, r.current_min_A);
  if (r.adjust == CompensationAdjust::Swing)
    return biased_sine(x, r.frequency_Hz, r.current_min_A + 0.5 * (r.reference_current_pp_A - x));
  return biased_sine(x * r.reference_current_pp_A, r.frequency_Hz, x * r.current_min_A);
}

// Largest drive whose peak |i| stays within max_current_A.
double max_drive(const CompensateRequest& r) {
  if (r.adjust == CompensationAdjust::Amplitude) return r.max_current_A - r.current_min_A;
  if (r.adjust == CompensationAdjust::Swing)
    return 2.0 * (r.max_current_A - std::fabs(r.current_min_A + 0.5 * r.reference_current_pp_A));
  const double peak =
      std::max(std::fabs(r.current_min_A), std::fabs(r.current_min_A + r.reference_current_pp_A));
  return r.max_current_A / peak;
}

double reference_drive(const CompensateRequest& r) {
  return r.adjust == CompensationAdjust::Scale ? 1.0 : r.reference_current_pp_A;
}

struct DriveRun {
  Metrics metrics;
  bool diverged = false;
  std::string error;
};

// The run of drive x at temperature T (run: simulate(), or a lane of the lock-step batch).
DriveRun run_drive(const detail::RunFn& run, const CompensateRequest& r, double T, double x) {
  SimulationSettings s;
  s.temperature_C = T;
  s.waveform = drive(r, x);
  s.periods = r.periods;
  s.dt_s = r.dt_s;
  s.record_every = 1;
  const Result res = run(s);
  DriveRun out;
  out.metrics = res.metrics;
  out.diverged = res.diverged;
  out.error = res.error;
  return out;
}

void validate_request(const Model& m, const CompensateRequest& r) {
  require_finite(r.reference_temperature_C, "reference temperature (--reference-temperature)",
                 "degC");
  require_positive_at_most(r.max_current_A, kMaxCurrent_A, "maximum current (--max-current)", "A");
  require_in(r.current_min_A, -r.max_current_A, r.max_current_A, "current minimum (--current-min)",
             "A");
  require_in(r.reference_current_pp_A, 0.0, 2.0 * kMaxCurrent_A,
             "reference current p-p (--reference-current-pp)", "A");
  if (!(r.reference_current_pp_A > 0.0))
    throw InputError("reference current peak-to-peak (--reference-current-pp) = 0 A: must be > 0");
  if (std::fabs(r.current_min_A + r.reference_current_pp_A) > r.max_current_A)
    throw InputError(fmt::format(
        "reference drive {} A + {} A p-p peaks at {} A, beyond the maximum current {} A",
        r.current_min_A, r.reference_current_pp_A, r.current_min_A + r.reference_current_pp_A,
        r.max_current_A));
  require_in(r.target_stroke_um, 0.0, kMaxTrackAmplitude_um, "target stroke (--target-stroke)",
             "um");
  if (r.temperatures_C.empty())
    throw InputError("compensate: no temperature given (--temperatures): give at least one");
  if (static_cast<double>(r.temperatures_C.size()) > kMaxListValues)
    throw InputError(fmt::format("compensate: {} temperatures (limit {:g})",
                                 r.temperatures_C.size(), kMaxListValues));
  for (std::size_t k = 0; k < r.temperatures_C.size(); ++k) {
    (void)make_conditions(m, r.temperatures_C[k]);  // finite, below T_c, above 0 K
    if (k > 0 && !(r.temperatures_C[k] > r.temperatures_C[k - 1]))
      throw InputError(fmt::format("compensate: temperatures must increase ({} after {} degC)",
                                   r.temperatures_C[k], r.temperatures_C[k - 1]));
  }
  (void)make_conditions(m, r.reference_temperature_C);
  require_positive(r.frequency_Hz, "frequency (--frequency)", "Hz");
  require_in(r.frequency_Hz, 0.0, kMaxFrequency_Hz, "frequency (--frequency)", "Hz");
  require_in(r.periods, 1.0, kMaxPeriods, "periods (--periods)");
  require_in(r.tolerance_um, 1e-9, 1e3, "stroke tolerance (--tolerance)", "um");
  if (!(r.dt_s >= 0.0) || !std::isfinite(r.dt_s))
    throw InputError(fmt::format("dt = {} s (--dt): must be >= 0 (0: the automatic rule)", r.dt_s));
  // Every drive the search may try is a valid run (step counts, currents).
  SimulationSettings s;
  s.waveform = drive(r, max_drive(r));
  s.periods = r.periods;
  s.dt_s = r.dt_s;
  validate(s);
  fields::check_request_fields(r);  // the table's rules (gmasim/experiments/experiment_fields.hpp)
}

// The drive x in (0, x_hi] whose stroke at temperature T is the target (a root of
// stroke(x) - target: bracketed from the reference drive, solved by TOMS 748), or x_hi when
// even that falls short. *reach: x_hi's run at T if already made.
CompensatePoint solve_point(const detail::RunFn& run_fn, const CompensateRequest& r, double T,
                            double target, double x_ref, double x_hi, const DriveRun* reach) {
  CompensatePoint p;
  p.temperature_C = T;
  int evals = 0;
  auto stroke = [&](double x) {
    ++evals;
    const DriveRun run = run_drive(run_fn, r, p.temperature_C, x);
    if (run.diverged) throw DivergenceError(run.error);
    return run.metrics;
  };
  try {
    p.uncompensated_stroke_um = stroke(x_ref).stroke_um;
    if (reach != nullptr && reach->diverged) throw DivergenceError(reach->error);
    const Metrics top = reach != nullptr ? reach->metrics : stroke(x_hi);
    p.reach_stroke_um = top.stroke_um;
    double x = x_hi;
    if (top.stroke_um < target) {
      p.reachable = false;  // the point holds the largest drive
    } else {
      // Bracket: the reference drive brackets from one side or the other; else the
      // search runs over (0, x_hi].
      double a = 1e-3 * x_ref, b = x_hi;
      double fa = std::nan(""), fb = top.stroke_um - target;
      const double f_ref = p.uncompensated_stroke_um - target;
      if (f_ref < 0.0) {
        a = x_ref;
        fa = f_ref;
      } else {
        b = x_ref;
        fb = f_ref;
        fa = stroke(a).stroke_um - target;
      }
      if (fb == 0.0) {
        x = b;
      } else if (fa >= 0.0) {
        x = a;  // even the smallest drive reaches the target
      } else {
        // Stop when the bracket is narrower than the drive change that moves the stroke by
        // the tolerance: at the steeper of the first bracket's secant and the secant of the
        // last two evaluations (a saturating stroke curve is steeper at the root than over
        // the first bracket).
        double slope = (fb - fa) / (b - a), x_last = std::nan(""), f_last = std::nan("");
        auto f = [&](double v) {
          const double fv = stroke(v).stroke_um - target;
          if (std::isfinite(x_last) && v != x_last)
            slope = std::max(slope, std::fabs((fv - f_last) / (v - x_last)));
          x_last = v;
          f_last = fv;
          return fv;
        };
        auto tol = [&](double lo, double hi) {
          return hi - lo <= 1e-12 * hi || (hi - lo) * slope < 0.5 * r.tolerance_um;
        };
        std::uintmax_t iters = 60;
        const auto [lo, hi] = boost::math::tools::toms748_solve(f, a, b, fa, fb, tol, iters);
        x = 0.5 * (lo + hi);
      }
    }
    const Metrics fin = stroke(x);
    const Waveform w = drive(r, x);
    p.current_pp_A = w.pp_A;
    p.current_min_A = w.min_A;
    p.current_max_A = w.min_A + w.pp_A;
    p.gain = x / x_ref;
    p.stroke_um = fin.stroke_um;
    p.hysteresis_um = fin.hysteresis_um;
    p.B_pp_T = fin.B_pp_T;
  } catch (const DivergenceError& e) {
    p.diverged = true;
    p.error = e.what();
  }
  p.evaluations = evals;
  return p;
}

constexpr std::pair<CompensationAdjust, const char*> kAdjustNames[] = {
    {CompensationAdjust::Amplitude, "amplitude"},
    {CompensationAdjust::Swing, "swing"},
    {CompensationAdjust::Scale, "scale"},
};

}  // namespace

const char* compensation_adjust_name(CompensationAdjust a) {
  for (const auto& [mode, name] : kAdjustNames)
    if (mode == a) return name;
  return "?";
}

CompensationAdjust parse_compensation_adjust(const std::string& name) {
  for (const auto& [mode, n] : kAdjustNames)
    if (name == n) return mode;
  throw InputError("adjust '" + clip_for_message(name) + "': must be amplitude, swing or scale");
}

CompensateResult run_compensate(const Model& m, const CompensateRequest& r,
                                const ProgressFn& progress) {
  validate_request(m, r);
  CompensateResult res;
  const auto wall0 = std::chrono::steady_clock::now();
  DriveRun ref;  // the reference run takes the path of the searches' runs (lanes or simulate())
  detail::lockstep_searches(m, 1, 1, r.lanes,
                            [&](std::size_t, const detail::RunFn& run) {
                              ref =
                                  run_drive(run, r, r.reference_temperature_C, reference_drive(r));
                            },
                            {});
  if (ref.diverged) throw DivergenceError("compensate: the reference drive diverged: " + ref.error);
  res.reference = ref.metrics;
  res.target_stroke_um = r.target_stroke_um > 0.0 ? r.target_stroke_um : ref.metrics.stroke_um;
  if (!(res.target_stroke_um > 0.0))
    throw InputError(
        "compensate: the reference drive (--reference-current-pp, --current-min) gives no stroke "
        "(0 um): no target; give a drive that moves the actuator");

  res.points.resize(r.temperatures_C.size());
  res.threads = resolve_thread_count(r.threads, r.temperatures_C.size());
  const double x_hi = max_drive(r);
  const double x_ref = reference_drive(r);
  // A default target is lowered to the smallest reach when the reference's stroke exceeds it:
  // the largest drive's run at each temperature first (its stroke is the envelope).
  std::vector<DriveRun> reach;
  if (r.target_stroke_um == 0.0 && r.lower_target_to_reach) {
    reach.resize(r.temperatures_C.size());
    detail::lockstep_searches(m, r.temperatures_C.size(), res.threads, r.lanes,
                              [&](std::size_t i, const detail::RunFn& run) {
                                reach[i] = run_drive(run, r, r.temperatures_C[i], x_hi);
                              },
                              {});
    for (const DriveRun& d : reach)
      if (!d.diverged && d.metrics.stroke_um < res.target_stroke_um) {
        res.target_stroke_um = d.metrics.stroke_um;
        res.target_lowered = true;
      }
  }
  // One search per temperature; in lanes, the searches' runs advance together (lockstep.hpp).
  detail::lockstep_searches(
      m, r.temperatures_C.size(), res.threads, r.lanes,
      [&](std::size_t i, const detail::RunFn& run) {
        res.points[i] = solve_point(run, r, r.temperatures_C[i], res.target_stroke_um, x_ref, x_hi,
                                    reach.empty() ? nullptr : &reach[i]);
      },
      progress);
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return res;
}

double schedule_gain(const CompensateResult& r, double T) {
  TemperatureFeedforward ff;
  for (const auto& p : r.points)
    if (p.reachable && !p.diverged) {
      ff.temperatures_C.push_back(p.temperature_C);
      ff.gains.push_back(p.gain);
    }
  if (ff.gains.empty())
    throw InputError("compensate: no temperature reached the target stroke: no schedule");
  return ff.gain_at(T);
}

TemperatureFeedforward loop_temperature_feedforward(const Model& m, const CompensateRequest& creq,
                                                    const TrackRequest& treq,
                                                    CompensateResult* schedule,
                                                    const ProgressFn& progress) {
  const double half = std::min(1.0, 0.5 * treq.current_limit_A);
  CompensateRequest q = creq;
  q.adjust = CompensationAdjust::Swing;
  q.current_min_A = treq.bias_A - half;
  q.reference_current_pp_A = 2.0 * half;
  q.target_stroke_um = 0.0;
  q.lower_target_to_reach = false;  // the gains are relative to the reference drive
  q.max_current_A = treq.current_limit_A;
  q.temperatures_C = treq.temperatures_C;
  std::sort(q.temperatures_C.begin(), q.temperatures_C.end());
  q.temperatures_C.erase(std::unique(q.temperatures_C.begin(), q.temperatures_C.end()),
                         q.temperatures_C.end());
  const CompensateResult res = run_compensate(m, q, progress);
  TemperatureFeedforward ff;
  for (const auto& p : res.points) {
    if (!p.reachable || p.diverged) continue;
    ff.temperatures_C.push_back(p.temperature_C);
    ff.gains.push_back(p.gain);
  }
  if (ff.gains.empty())
    throw InputError("compensate: no track temperature reached the target stroke: no schedule");
  ff.static_gain_um_per_A = res.reference.stroke_um / q.reference_current_pp_A;
  if (schedule != nullptr) *schedule = res;
  return ff;
}

CompensatedTrack run_compensated_track(const Model& m, const CompensateRequest& creq,
                                       TrackRequest treq, const ProgressFn& progress) {
  CompensatedTrack out;
  const TemperatureFeedforward ff =
      loop_temperature_feedforward(m, creq, treq, &out.loop_schedule, progress);
  out.static_gain_um_per_A = ff.static_gain_um_per_A;
  treq.feedforward = {};
  out.plain = run_track(m, treq, progress);
  treq.feedforward = ff;
  out.compensated = run_track(m, treq, progress);
  return out;
}

TrackRequest compensate_track_request(const CompensateRequest& creq) {
  const CompensateTracking& k = creq.tracking;
  for (double A : k.amplitudes_um)
    require_positive_at_most(A, kMaxTrackAmplitude_um, "tracking amplitude (--track-amplitudes)",
                             "um");
  for (double f : k.frequencies_Hz)
    require_positive_at_most(f, kMaxFrequency_Hz, "tracking frequency (--track-frequencies)", "Hz");
  require_positive_at_most(k.current_limit_A, kMaxCurrent_A,
                           "tracking current limit (--current-limit)", "A");
  require_in(k.bias_A, -k.current_limit_A, k.current_limit_A, "tracking bias current (--bias)",
             "A");
  TrackRequest t;
  t.temperatures_C = k.temperatures_C.empty() ? creq.temperatures_C : k.temperatures_C;
  t.amplitudes_um = k.amplitudes_um;
  t.frequencies_Hz = k.frequencies_Hz;
  t.bias_A = k.bias_A;
  t.current_limit_A = k.current_limit_A;
  t.threads = creq.threads;
  return t;
}

CompensatedTrack run_compensated_track(const Model& m, const CompensateRequest& creq,
                                       const ProgressFn& progress) {
  return run_compensated_track(m, creq, compensate_track_request(creq), progress);
}

double coil_copper_loss_W(const Model& m, double i_min_A, double i_pp_A, double T_C) {
  const double mean = i_min_A + 0.5 * i_pp_A, amp = 0.5 * i_pp_A;
  return (mean * mean + 0.5 * amp * amp) * coil_resistance_ohm(m.thermal_network, m.T_ref_C, T_C);
}

ScheduleHeating schedule_heating(const Model& m, const CompensateResult& res) {
  ScheduleHeating h;
  for (const auto& p : res.points) {
    if (p.diverged) continue;
    const double P = coil_copper_loss_W(m, p.current_min_A, p.current_pp_A, p.temperature_C);
    if (P > h.max_copper_loss_W) {
      h.max_copper_loss_W = P;
      h.at_temperature_C = p.temperature_C;
    }
  }
  h.steady_rise_K = h.max_copper_loss_W / m.thermal_network.G_housing_ambient_W_per_K;
  return h;
}

Report compensate_report(const Model& m, const CompensateRequest& req, const CompensateResult& res,
                         const CompensatedTrack* track) {
  Report r;
  r.experiment = "compensate";
  r.meta.emplace_back("model", m.spec.source);
  fields::add_request_meta(r,
                           req);  // the request's table (gmasim/experiments/experiment_fields.hpp)
  fields::insert_meta_after(r, "frequency_Hz", "target_stroke_um", res.target_stroke_um);
  fields::insert_meta_after(r, "target_stroke_um", "reference_stroke_um", res.reference.stroke_um);
  fields::insert_meta_after(r, "reference_stroke_um", "target_lowered_to_reach",
                            res.target_lowered);
  const ScheduleHeating heat = schedule_heating(m, res);
  r.meta.emplace_back("max_copper_loss_W", heat.max_copper_loss_W);
  r.meta.emplace_back("steady_rise_K", heat.steady_rise_K);
  r.meta.emplace_back("wall_time_s", res.wall_time_s);
  Table t;
  t.name = "schedule";
  t.columns = {"temperature_C",
               "current_pp_A",
               "current_min_A",
               "current_max_A",
               "gain",
               "stroke_um",
               "uncompensated_stroke_um",
               "reach_stroke_um",
               "hysteresis_um",
               "B_pp_T",
               "copper_loss_W",
               "evaluations",
               "reachable",
               "status",
               "error"};
  const double nan = std::nan("");
  for (const auto& p : res.points) {
    const bool ok = !p.diverged;
    t.rows.push_back(
        {p.temperature_C, ok ? p.current_pp_A : nan, ok ? p.current_min_A : nan,
         ok ? p.current_max_A : nan, ok ? p.gain : nan, ok ? p.stroke_um : nan,
         ok ? p.uncompensated_stroke_um : nan, ok ? p.reach_stroke_um : nan,
         ok ? p.hysteresis_um : nan, ok ? p.B_pp_T : nan,
         ok ? coil_copper_loss_W(m, p.current_min_A, p.current_pp_A, p.temperature_C) : nan,
         p.evaluations, p.reachable, p.diverged ? "diverged" : "ok", p.error});
  }
  r.tables.push_back(std::move(t));
  if (track != nullptr) {
    r.meta.emplace_back("track_static_gain_um_per_A", track->static_gain_um_per_A);
    Table k;
    k.name = "track";
    k.columns = {"temperature_C",       "amplitude_um",     "frequency_Hz",
                 "error_rms_um_pid",    "error_rms_um_ff",  "error_change_pct_pid",
                 "error_change_pct_ff", "feedforward_gain", "saturated_pid",
                 "saturated_ff"};
    for (std::size_t i = 0; i < track->plain.points.size(); ++i) {
      const TrackPoint& a = track->plain.points[i];
      const TrackPoint& b = track->compensated.points[i];
      k.rows.push_back({a.temperature_C, a.amplitude_um, a.frequency_Hz, a.error_rms_um,
                        b.error_rms_um, a.error_change_pct, b.error_change_pct, b.feedforward_gain,
                        a.saturated, b.saturated});
    }
    r.tables.push_back(std::move(k));
  }
  return r;
}

}  // namespace gmasim
