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
#include "gmasim/validate.hpp"

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

// Moves the model by one step (dt > 0) or one quasi-static increment (dt = 0) to a drive
// value of the record: a coil current, or the applied field H_c of one rod (eq. 7), for
// which the coil current that produces it at the end of the step is found by bracketing
// and TOMS 748 (each trial is the step itself, from a copy of the state).
class Driver {
 public:
  Driver(const Model& m, const Conditions& c, const Measurement& meas, std::size_t rod)
      : m_(m), c_(c), field_(meas.drive_kind == DriveInput::Field), rod_(rod), path_(meas.path) {}

  void move(State& st, double drive, double dt) {
    if (!field_) {
      advance(st, drive, dt);
      return;
    }
    advance(st, current_for_field(st, drive, dt), dt);
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

  double current_for_field(const State& st, double target, double dt) {
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
  bool field_;
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

double record_step_count(const Measurement& meas, const ObjectiveSettings& s) {
  const auto& c = meas.condition;
  const double passes = 1.0 + static_cast<double>(c.precycles);
  if (c.quasi_static) {
    const double inc = peak_to_peak(meas.drive) / s.quasi_static_increments;
    double n = std::ceil(std::fabs(meas.drive.front()) / inc);  // a field record's ramp
    for (std::size_t i = 1; i < meas.drive.size(); ++i)
      n += std::max(1.0, std::ceil(std::fabs(meas.drive[i] - meas.drive[i - 1]) / inc - 1e-9));
    n += std::ceil(std::fabs(meas.drive.front() - meas.drive.back()) / inc);
    return passes * n;
  }
  const double span = meas.t_s.back() - meas.t_s.front();
  const double dt = objective_step(s, meas.periodic() ? 1.0 / c.frequency_Hz : 0.0);
  return passes * std::max(1.0, std::ceil(span / dt - 1e-9));
}

void run_record(const Model& m, const Conditions& c, State st, const Measurement& meas,
                const ObjectiveSettings& s, std::vector<double>& response, std::vector<double>* B_T,
                std::vector<double>* H_A_per_m) {
  const auto& ts = meas.t_s;
  const std::size_t n = ts.size();
  const auto& cond = meas.condition;
  const std::size_t rod = record_rod(m, meas);
  const Probe probe{meas.response_kind == ResponseOutput::Strain, rod, c.rods[rod].length_m};
  Driver driver(m, c, meas, rod);
  response.resize(n);
  if (B_T) B_T->resize(n);
  if (H_A_per_m) H_A_per_m->resize(n);
  auto field = [&](const State& x) { return x.rods[rod].Hc_A_per_m; };
  auto store = [&](std::size_t i, const State& x) {  // sample i from the state x
    response[i] = probe.response(x);
    if (B_T) (*B_T)[i] = x.B_T;
    if (H_A_per_m) (*H_A_per_m)[i] = field(x);
  };
  const long passes = 1 + cond.precycles;
  // Moves quasi-statically from the drive value `from` to `to` in equal increments of at
  // most (drive range) / quasi_static_increments.
  const double inc = std::max(peak_to_peak(meas.drive), 1e-300) / s.quasi_static_increments;
  auto travel = [&](double from, double to) {
    const long k_n = std::max(1L, checked_ceil_count(std::fabs(to - from) / inc - 1e-9, kMaxSteps,
                                                     meas.path + ": quasi-static increments"));
    for (long k = 1; k <= k_n; ++k)
      driver.move(st, from + (to - from) * static_cast<double>(k) / static_cast<double>(k_n), 0.0);
  };
  // A field record starts at rest at zero current and ramps quasi-statically to its first
  // field, as a current record starts at rest at its first current (make_state).
  if (meas.drive_kind == DriveInput::Field && field(st) != meas.drive.front())
    travel(field(st), meas.drive.front());

  if (cond.quasi_static) {
    double at = meas.drive.front();
    for (long pass = 0; pass < passes; ++pass) {
      if (pass > 0) travel(at, meas.drive.front());
      at = meas.drive.front();
      for (std::size_t i = 0; i < n; ++i) {
        if (i > 0) travel(at, meas.drive[i]);
        at = meas.drive[i];
        if (pass + 1 == passes) store(i, st);
      }
    }
    return;
  }

  const double t0 = ts.front(), t1 = ts.back();
  const bool sine = cond.current_source == "sine";
  const Waveform w =
      sine ? biased_sine(cond.current_pp_A, cond.frequency_Hz, cond.current_min_A) : Waveform{};
  TableDrive table{ts, meas.drive};
  auto drive = [&](double t) { return sine ? w.current_at(t) : table(t); };
  const double dt_target = objective_step(s, meas.periodic() ? 1.0 / cond.frequency_Hz : 0.0);
  const long nsteps = std::max(1L, checked_ceil_count((t1 - t0) / dt_target, kMaxSteps,
                                                      meas.path + ": steps over the record"));
  const double dt = (t1 - t0) / static_cast<double>(nsteps);
  st.t_s = t0;
  for (long pass = 0; pass < passes; ++pass) {
    const bool last = pass + 1 == passes;
    std::size_t j = 0;
    table.j = 1;
    for (; j < n && ts[j] <= t0; ++j)
      if (last) store(j, st);
    double r_prev = probe.si(st), B_prev = st.B_T, H_prev = field(st), t_prev = t0;
    st.t_s = t0;
    for (long k = 1; k <= nsteps; ++k) {
      const double t = k == nsteps ? t1 : t0 + static_cast<double>(k) * dt;
      driver.move(st, drive(t), t - t_prev);
      st.t_s = t;
      const double r_now = probe.si(st);
      while (last && j < n && ts[j] <= t) {
        const double f = (ts[j] - t_prev) / (t - t_prev);
        response[j] = (r_prev + f * (r_now - r_prev)) * 1e6;
        if (B_T) (*B_T)[j] = B_prev + f * (st.B_T - B_prev);
        if (H_A_per_m) (*H_A_per_m)[j] = H_prev + f * (field(st) - H_prev);
        ++j;
      }
      r_prev = r_now;
      B_prev = st.B_T;
      H_prev = field(st);
      t_prev = t;
    }
    for (; last && j < n; ++j) store(j, st);
  }
}

void apply_offset(OffsetMode mode, const std::vector<double>& measured, std::size_t begin,
                  std::vector<double>& simulated) {
  switch (mode) {
    case OffsetMode::Absolute:
      return;
    case OffsetMode::FirstSample: {
      const double shift = measured.front() - simulated.front();
      for (double& v : simulated) v += shift;
      return;
    }
    case OffsetMode::Fitted: {
      // The constant c minimising sum_i (sim_i + c - meas_i)^2 over the compared samples.
      double sum = 0.0;
      for (std::size_t i = begin; i < measured.size(); ++i) sum += measured[i] - simulated[i];
      const double shift = sum / static_cast<double>(measured.size() - begin);
      for (double& v : simulated) v += shift;
      return;
    }
  }
}

}  // namespace gmasim::identify_detail
