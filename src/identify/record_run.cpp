// Simulating one measurement record (docs/data.md, "What is simulated and compared"):
// current- or field-driven, timed or quasi-static, optionally pre-cycled; the response is
// the actuator output or one rod's strain, with the record's offset rule applied after.
#include "identify/record_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <cstdint>

#include "gmasim/errors.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/simulate/run_loop.hpp"

namespace gmasim::identify_detail {
namespace {

// Linear interpolation of a sampled drive, with a forward-moving index (time only
// increases during a pass): O(1) per call, no allocation.
struct TableDrive {
  const std::vector<double>& t;
  const std::vector<double>& v;
  std::size_t j = 1;
  double operator()(double time) {
    if (time <= t.front()) return v.front();
    if (time >= t.back()) return v.back();
    while (j + 1 < t.size() && t[j] < time) ++j;
    while (j > 1 && t[j - 1] > time) --j;
    const double f = (time - t[j - 1]) / (t[j] - t[j - 1]);
    return v[j - 1] + f * (v[j] - v[j - 1]);
  }
};

// The coil current that gives one rod the applied field H_c (eq. 7) of a field record at the
// end of a step (dt > 0) or of a quasi-static increment (dt = 0): found by bracketing and
// TOMS 748, each trial being that step itself, from a copy of the state.
class FieldSolver {
 public:
  FieldSolver(const Model& m, const Conditions& c, const Measurement& meas, std::size_t rod)
      : m_(m), c_(c), rod_(rod), path_(meas.path) {}

  double current_for(const State& st, double target, double dt) {
    if (dI_dH_ == 0.0) {  // first call: the slope of the circuit from a 1 mA probe
      const double h0 = field_error(st, st.current_A, 0.0, dt);
      const double h1 = field_error(st, st.current_A + 1e-3, 0.0, dt);
      if (!(std::fabs(h1 - h0) > 0.0))
        throw InputError(located(path_, 0,
                                 "the coil current does not move the field of the record's rod: "
                                 "this model cannot be driven by field_A_per_m"));
      dI_dH_ = 1e-3 / (h1 - h0);
    }
    const double tol_A_per_m = 1e-9 * std::max(1.0, std::fabs(target));
    double a = st.current_A + dI_dH_ * (target - st.rods[rod_].Hc_A_per_m);
    a = std::clamp(a, -kMaxCurrent_A, kMaxCurrent_A);
    double fa = field_error(st, a, target, dt);
    if (std::fabs(fa) <= tol_A_per_m) return a;
    // Bracket: move against the error, doubling, within the current limit.
    const double dir = (fa > 0.0) == (dI_dH_ > 0.0) ? -1.0 : 1.0;
    double d = std::max(2.0 * std::fabs(dI_dH_ * fa), 1e-6);
    double b = a, fb = fa;
    for (int k = 0; k < 80; ++k) {
      b = std::clamp(a + dir * d, -kMaxCurrent_A, kMaxCurrent_A);
      fb = field_error(st, b, target, dt);
      if ((fb > 0.0) != (fa > 0.0) || std::fabs(fb) <= tol_A_per_m) break;
      if (std::fabs(b) >= kMaxCurrent_A) break;
      a = b;
      fa = fb;
      d *= 2.0;
    }
    if (std::fabs(fb) <= tol_A_per_m) return b;
    if ((fb > 0.0) == (fa > 0.0))
      throw DivergenceError(
          st.t_s, m_.rods[rod_].name, "field_A_per_m [A/m] of the record", target,
          fmt::format("no coil current within +-{:g} A produces it", kMaxCurrent_A));
    return solve(st, target, dt, a, fa, b, fb);
  }

 private:
  void advance(State& s, double current_A, double dt) const {
    if (dt > 0.0) {
      step(m_, c_, s, {current_A, dt});
    } else {
      quasi_static_step(m_, c_, s, current_A);
    }
  }

  double field_error(const State& st, double current_A, double target, double dt) {
    trial_ = st;
    advance(trial_, current_A, dt);
    return trial_.rods[rod_].Hc_A_per_m - target;
  }

  // TOMS 748 inside the bracket [a, b]; the secant of the bracket is the next first guess.
  double solve(const State& st, double target, double dt, double a, double fa, double b,
               double fb) {
    auto tol = [&](double lo, double hi) {
      return std::fabs(hi - lo) <= 1e-13 * std::max(1.0, std::fabs(lo));
    };
    std::uintmax_t iters = 60;
    const auto [lo, hi] = boost::math::tools::toms748_solve(
        [&](double v) { return field_error(st, v, target, dt); }, std::min(a, b), std::max(a, b),
        a < b ? fa : fb, a < b ? fb : fa, tol, iters);
    const double root = 0.5 * (lo + hi);
    if (std::fabs(b - a) > 0.0) dI_dH_ = (b - a) / (fb - fa);  // secant: next guess
    return root;
  }

  const Model& m_;
  const Conditions& c_;
  std::size_t rod_;
  std::string path_;
  State trial_;
  double dI_dH_ = 0.0;
};

// What the record measured, from the state, in SI (the output y [m] or the rod's strain
// x_i / l_i [-]); the record's unit is 1e6 times it (um, ppm).
struct Probe {
  bool strain;
  std::size_t rod;
  double length_m;
  double si(const State& st) const { return strain ? st.rods[rod].x_m / length_m : st.y_m; }
  double response(const State& st) const { return si(st) * 1e6; }
};

}  // namespace

double objective_step(const ObjectiveSettings& s, double period_s) {
  if (s.dt_s > 0.0) return s.dt_s;
  if (period_s > 0.0) return period_s / s.steps_per_period;
  return kMaxDt_s;
}

std::size_t record_rod(const Model& m, const Measurement& meas) {
  const std::string& name = meas.condition.rod;
  if (name.empty()) return 0;
  std::string names;
  for (std::size_t i = 0; i < m.rods.size(); ++i) {
    if (m.rods[i].name == name) return i;
    names += (i ? ", " : "") + m.rods[i].name;
  }
  throw InputError(
      located(meas.path, 0,
              fmt::format("rod = '{}' is not a rod of the model (its rods: {})", name, names)));
}

double record_initial_current(const Measurement& meas) {
  const auto& c = meas.condition;
  if (meas.drive_kind == DriveInput::Field) return 0.0;  // the field is reached by a ramp
  if (c.current_source == "sine")
    return biased_sine(c.current_pp_A, c.frequency_Hz, c.current_min_A)
        .current_at(meas.t_s.front());
  return meas.drive.front();
}

double record_drive_amplitude(const Measurement& meas) {
  const auto& c = meas.condition;
  if (meas.drive_kind == DriveInput::Current && c.current_source == "sine")
    return std::max(std::fabs(c.current_min_A), std::fabs(c.current_min_A + c.current_pp_A));
  double a = 0.0;
  for (double v : meas.drive) a = std::max(a, std::fabs(v));
  return a;
}

double record_step_count(const Measurement& meas, const ObjectiveSettings& s) {
  const auto& c = meas.condition;
  const double passes = 1.0 + static_cast<double>(c.precycles);
  // The initial cycle's quasi-static increments (about 4 A / (range / increments) + 3).
  const double initial =
      c.initial_state == InitialState::Demagnetised
          ? 0.0
          : 4.0 * record_drive_amplitude(meas) /
                    std::max(peak_to_peak(meas.drive) / s.quasi_static_increments, 1e-300) +
                3.0;
  if (c.quasi_static) {
    const double inc = peak_to_peak(meas.drive) / s.quasi_static_increments;
    double n = std::ceil(std::fabs(meas.drive.front()) / inc);  // a field record's ramp
    for (std::size_t i = 1; i < meas.drive.size(); ++i)
      n += std::max(1.0, std::ceil(std::fabs(meas.drive[i] - meas.drive[i - 1]) / inc - 1e-9));
    n += std::ceil(std::fabs(meas.drive.front() - meas.drive.back()) / inc);
    return passes * n + initial;
  }
  const double span = meas.t_s.back() - meas.t_s.front();
  const double dt = objective_step(s, meas.periodic() ? 1.0 / c.frequency_Hz : 0.0);
  return passes * std::max(1.0, std::ceil(span / dt - 1e-9)) + initial;
}

namespace {

// One simulation of a record: what it drives, what it measures, where the samples go.
class RecordRun {
 public:
  RecordRun(const Model& m, const Conditions& c, const Measurement& meas,
            const ObjectiveSettings& s, std::vector<double>& response, std::vector<double>* B_T,
            std::vector<double>* H_A_per_m)
      : m_(m),
        c_(c),
        meas_(meas),
        s_(s),
        rod_(record_rod(m, meas)),
        probe_{meas.response_kind == ResponseOutput::Strain, rod_, c.rods[rod_].length_m},
        solver_(m, c, meas, rod_),
        field_drive_(meas.drive_kind == DriveInput::Field),
        response_(response),
        B_T_(B_T),
        H_(H_A_per_m),
        // Quasi-static moves: equal increments of at most (drive range) / increments.
        inc_(std::max(peak_to_peak(meas.drive), 1e-300) / s.quasi_static_increments),
        increments_what_(meas.path + ": quasi-static increments") {
    const std::size_t n = meas.t_s.size();
    response_.resize(n);
    if (B_T_) B_T_->resize(n);
    if (H_) H_->resize(n);
  }

  void run(State& st) {
    if (meas_.condition.initial_state != InitialState::Demagnetised) {
      initial_cycle(st);
    } else if (field_drive_ && field(st) != meas_.drive.front()) {
      // A field record starts at rest at zero current and ramps quasi-statically to its first
      // field, as a current record starts at rest at its first current (make_state).
      try {
        travel(st, field(st), meas_.drive.front());
      } catch (const DivergenceError& e) {
        throw DivergenceError(fmt::format("{}: the ramp from rest to data row 1 ({} = {:g}): {}",
                                          meas_.path, meas_.drive_column(), meas_.drive.front(),
                                          e.what()));
      }
    }
    if (meas_.condition.quasi_static) {
      run_quasi_static(st);
    } else {
      run_timed(st);
    }
  }

 private:
  double field(const State& x) const { return x.rods[rod_].Hc_A_per_m; }

  void store(std::size_t i, const State& x) {  // sample i from the state x
    response_[i] = probe_.response(x);
    if (B_T_) (*B_T_)[i] = x.B_T;
    if (H_) (*H_)[i] = field(x);
  }

  // The coil current of a drive value (a current, or a field the solver produces).
  double current(const State& x, double drive, double dt) {
    return field_drive_ ? solver_.current_for(x, drive, dt) : drive;
  }

  // Moves quasi-statically from the drive value `from` to `to` in equal increments.
  void travel(State& st, double from, double to) {
    const StepGrid g = StepGrid::quasi_static(
        steps_to_resolve(std::fabs(to - from) / inc_ - 1e-9, 1, increments_what_),
        increments_what_);
    const double k_n = static_cast<double>(g.steps);
    run_loop(m_, c_, st, g, [&](const State& x, const StepPoint& p) {
      return current(x, from + (to - from) * static_cast<double>(p.k) / k_n, 0.0);
    });
  }

  // initial_state: a slow bipolar cycle of the record's amplitude from the rest state,
  // 0 -> +A -> -A -> first drive value (negative remanence; the mirror for positive).
  void initial_cycle(State& st) {
    const double A = record_drive_amplitude(meas_);
    const double s = meas_.condition.initial_state == InitialState::NegativeRemanence ? 1.0 : -1.0;
    const double first = field_drive_ ? meas_.drive.front() : record_initial_current(meas_);
    const double path[] = {field_drive_ ? field(st) : st.current_A, s * A, -s * A, first};
    try {
      for (int k = 0; k < 3; ++k) travel(st, path[k], path[k + 1]);
    } catch (const DivergenceError& e) {
      throw DivergenceError(
          fmt::format("{}: the initial cycle of initial_state = {} ({} to {:g}, "
                      "{:g} and {:g}): {}",
                      meas_.path, initial_state_name(meas_.condition.initial_state),
                      meas_.drive_column(), s * A, -s * A, first, e.what()));
    }
  }

  void run_quasi_static(State& st) {
    const auto& drive = meas_.drive;
    const long passes = 1 + meas_.condition.precycles;
    double at = drive.front();
    for (long pass = 0; pass < passes; ++pass) {
      if (pass > 0) travel(st, at, drive.front());
      at = drive.front();
      for (std::size_t i = 0; i < drive.size(); ++i) {
        try {
          if (i > 0) travel(st, at, drive[i]);
        } catch (const DivergenceError& e) {
          // A quasi-static record has no time: name the sample (issue 19, item 11), not "t = 0".
          throw DivergenceError(fmt::format(
              "{}: quasi-static record, moving to data row {} ({} = {:g}, pass {} of {}): {}",
              meas_.path, i + 1, meas_.drive_column(), drive[i], pass + 1, passes, e.what()));
        }
        at = drive[i];
        if (pass + 1 == passes) store(i, st);
      }
    }
  }

  // Steps spanning [t0, t1] exactly (the record's first and last time); the samples between
  // two steps are interpolated linearly. Every pre-cycle repeats the record from t0.
  void run_timed(State& st) {
    const auto& ts = meas_.t_s;
    const std::size_t n = ts.size();
    const auto& cond = meas_.condition;
    const double t0 = ts.front(), t1 = ts.back();
    const bool sine = cond.current_source == "sine";
    const Waveform w =
        sine ? biased_sine(cond.current_pp_A, cond.frequency_Hz, cond.current_min_A) : Waveform{};
    TableDrive table{ts, meas_.drive};
    const double dt_target = objective_step(s_, meas_.periodic() ? 1.0 / cond.frequency_Hz : 0.0);
    const std::string what = meas_.path + ": steps over the record";
    const StepGrid grid =
        StepGrid::spanning(t0, t1, steps_to_resolve((t1 - t0) / dt_target, 1, what), what);
    auto drive = [&](const State& x, const StepPoint& p) {
      return current(x, sine ? w.current_at(p.t_s) : table(p.t_s), p.dt_s);
    };
    const long passes = 1 + cond.precycles;
    st.t_s = t0;
    for (long pass = 0; pass < passes; ++pass) {
      const bool last = pass + 1 == passes;
      std::size_t j = 0;
      table.j = 1;
      for (; j < n && ts[j] <= t0; ++j)
        if (last) store(j, st);
      double r_prev = probe_.si(st), B_prev = st.B_T, H_prev = field(st), t_prev = t0;
      run_loop(m_, c_, st, grid, drive, [&](const State& x, const StepPoint& p) {
        const double t = p.t_s, r_now = probe_.si(x);
        while (last && j < n && ts[j] <= t) {
          const double f = (ts[j] - t_prev) / (t - t_prev);
          response_[j] = (r_prev + f * (r_now - r_prev)) * 1e6;
          if (B_T_) (*B_T_)[j] = B_prev + f * (x.B_T - B_prev);
          if (H_) (*H_)[j] = H_prev + f * (field(x) - H_prev);
          ++j;
        }
        r_prev = r_now;
        B_prev = x.B_T;
        H_prev = field(x);
        t_prev = t;
      });
      for (; last && j < n; ++j) store(j, st);
    }
  }

  const Model& m_;
  const Conditions& c_;
  const Measurement& meas_;
  const ObjectiveSettings& s_;
  std::size_t rod_;
  Probe probe_;
  FieldSolver solver_;
  bool field_drive_;
  std::vector<double>& response_;
  std::vector<double>* B_T_;
  std::vector<double>* H_;
  double inc_;
  std::string increments_what_;
};

}  // namespace

Model with_record_preload(const Model& m, const MeasurementCondition& c) {
  if (std::isnan(c.prestress_MPa))
    throw InputError(fmt::format("record '{}': no prestress_MPa condition", c.label));
  Model mp = m;
  mp.preload_N = c.prestress_MPa * 1e6 * preload_area_m2(m.spec);
  check_model_validity(mp);
  return mp;
}

void run_record(const Model& m, const Conditions& c, State st, const Measurement& meas,
                const ObjectiveSettings& s, std::vector<double>& response, std::vector<double>* B_T,
                std::vector<double>* H_A_per_m) {
  RecordRun(m, c, meas, s, response, B_T, H_A_per_m).run(st);
}

double apply_offset(OffsetMode mode, const std::vector<double>& measured, std::size_t begin,
                    std::vector<double>& simulated) {
  switch (mode) {
    case OffsetMode::Absolute:
      return 0.0;
    case OffsetMode::FirstSample: {
      const double shift = measured.front() - simulated.front();
      for (double& v : simulated) v += shift;
      return shift;
    }
    case OffsetMode::Fitted: {
      // The constant c minimising sum_i (sim_i + c - meas_i)^2 over the compared samples.
      double sum = 0.0;
      for (std::size_t i = begin; i < measured.size(); ++i) sum += measured[i] - simulated[i];
      const double shift = sum / static_cast<double>(measured.size() - begin);
      for (double& v : simulated) v += shift;
      return shift;
    }
  }
  return 0.0;
}

}  // namespace gmasim::identify_detail
