// The one fixed-step run loop (issue 10). Every time loop of the library runs through
// run_loop(): simulate() (and with it sweep, ablate, compensate, params-vs-temperature and
// `model check`), identify's measurement records and sine targets, track's plant between
// controller samples, the stepped-sine FRF and the DC settling of the FRF bias point; the
// sample-by-sample Stepper takes the loop's single step, run_loop_step(). (A field-driven
// record's root solve tries single steps from a copy of the state; that is no time loop.)
//
//   StepGrid   where the steps lie in time, built by one of its factories, which apply the
//              step-count limit (kMaxSteps, gmasim/model/validate.hpp) in one place;
//   drive      the coil current of each step: a function of the step's end time,
//              `double(double t_s)`, or of the state and the step,
//              `double(const State&, const StepPoint&)` (a field-driven record solves for the
//              current; a sampled controller computes it at the first step of its sample and
//              holds it);
//   recorder   `void(const State&, const StepPoint&)`, called after every step with the state
//              at the step's end (NoRecorder records nothing).
//
// Drive and recorder are template parameters, not virtual calls: the loop is the hot path,
// inlines both, and allocates nothing (tests/test_run_loop.cpp counts). It owns the step
// times, sets State::t_s to the grid time after each step (no drift from repeated addition),
// and checks that the drive current and the outputs y and B are finite (DivergenceError
// naming the time and the quantity), and that every rod's state is physically possible
// (check_physical_validity: strain, displacement, flux density within their bounds; issue 19).
// step() checks every rod's H, M and x itself.
#pragma once

#include <cmath>
#include <concepts>
#include <string_view>
#include <type_traits>
#include <utility>

#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/model/validity.hpp"

namespace gmasim {

// How a grid places its steps. Each clock is the floating-point recipe of the loops it
// replaced, kept operation for operation so that their results stay bit-identical.
enum class StepClock {
  // t_k = t0 + k dt, k = 1..steps; step() gets dt. (simulate, the FRF, identify's targets)
  Uniform,
  // t_k = t0 + k dt for k < steps and t_steps = t1 exactly, dt = (t1 - t0) / steps; step()
  // gets t_k - t_{k-1}. A record's samples are interpolated between steps that span exactly
  // [t0, t1]. (identify's timed records)
  Spanning,
  // Held samples of length T_s, each of `substeps` steps of dt = T_s / substeps: the step q
  // (1..substeps) of sample j ends at t = (t0 + j T_s) + q dt; step() gets dt. A sampled
  // controller computes the current at the sample time t0 + j T_s. (track)
  Sampled,
  // Increments of quasi_static_step(): no time; State::t_s is left as it is and step points
  // carry it with dt = 0. (identify's quasi-static records and field ramps)
  QuasiStatic,
};

struct StepGrid {
  StepClock clock = StepClock::Uniform;
  double t0_s = 0.0;      // start (timed clocks): the loop sets State::t_s to it first
  double dt_s = 0.0;      // Uniform, Sampled: the step; Spanning: (t1 - t0) / steps
  double t1_s = 0.0;      // Spanning: the exact end time
  double sample_s = 0.0;  // Sampled: T_s
  long substeps = 1;      // Sampled: steps per sample
  long steps = 0;         // steps in all (Sampled: samples * substeps)

  // Every factory checks the count against kMaxSteps (InputError "<what> = <n>: too many
  // (limit 2e+08)") before it becomes an integer. Counts come in as doubles: products of
  // counts are formed in floating point, so that an overflow is refused, not wrapped.
  //
  // Uniform: `steps` steps of dt_s from t0_s (rounded to the nearest integer).
  static StepGrid uniform(double t0_s, double dt_s, double steps, std::string_view what);
  // Uniform: the steps of dt_s that cover duration_s, rounded to the nearest whole step, at
  // least 1 (checked_step_count: "<what>: <n> steps of <dt> s over <duration> s: too many").
  static StepGrid covering(double t0_s, double duration_s, double dt_s, std::string_view what);
  // Spanning: `steps` steps from t0_s to exactly t1_s.
  static StepGrid spanning(double t0_s, double t1_s, double steps, std::string_view what);
  // Sampled: `samples` samples of sample_s from t0_s, each `substeps` steps (both >= 1);
  // the samples and the steps in all are checked.
  static StepGrid sampled(double t0_s, double sample_s, double samples, long substeps,
                          std::string_view what);
  // QuasiStatic: `increments` calls of quasi_static_step().
  static StepGrid quasi_static(double increments, std::string_view what);

  long samples() const { return clock == StepClock::Sampled ? steps / substeps : steps; }
  // Sampled: the time of sample j, t0 + j T_s (where a sampled drive reads its inputs).
  double sample_time(long j) const { return t0_s + static_cast<double>(j) * sample_s; }
};

// The steps (or periods, samples) that resolve a span with steps no longer than a target,
// given their quotient x = span / target: ceil(x) with a 1e-9 tolerance (checked_ceil_count),
// at least at_least, at most kMaxSteps. The one rounding rule of "steps per period".
long steps_to_resolve(double x, long at_least, std::string_view what);

// One step of a grid, as the drive and the recorder see it.
struct StepPoint {
  long k = 0;         // 1..steps
  double t_s = 0.0;   // the step's end time (State::t_s after it); QuasiStatic: State::t_s
  double dt_s = 0.0;  // the step length given to step(); QuasiStatic: 0
  long sample = 0;    // Sampled: the sample j it belongs to (0-based); other clocks: k - 1
  long substep = 1;   // Sampled: 1..substeps within its sample; other clocks: 1
};

// What run_loop() accepts as a drive and as a recorder (clang-format 14 does not know
// concepts, hence the guard).
// clang-format off
template <class D>
concept TimeDrive = requires(D& d, double t) {
  { d(t) } -> std::convertible_to<double>;
};
template <class D>
concept StateDrive = requires(D& d, const State& s, const StepPoint& p) {
  { d(s, p) } -> std::convertible_to<double>;
};
template <class D>
concept StepDrive = TimeDrive<D> || StateDrive<D>;
template <class R>
concept StepRecorder = std::invocable<R&, const State&, const StepPoint&>;
// clang-format on

// A current held for the whole grid (the DC settling of the FRF bias point).
struct HeldCurrent {
  double current_A = 0.0;
  double operator()(double) const { return current_A; }
};

struct NoRecorder {
  void operator()(const State&, const StepPoint&) const noexcept {}
};

namespace run_loop_detail {
// Throws DivergenceError(t_s, "", quantity, value, "not finite"); out of line, off the hot path.
[[noreturn]] void throw_not_finite(double t_s, const char* quantity, double value);

template <class D>
double current_of(D& drive, const State& st, const StepPoint& p) {
  if constexpr (StateDrive<D>) {
    return static_cast<double>(drive(st, p));
  } else {
    return static_cast<double>(drive(p.t_s));
  }
}

// One step of the grid: the drive's current (checked), step() or quasi_static_step(), the
// grid time, the outputs (checked), the recorder.
template <class Law, bool kQuasiStatic, class D, class R>
inline void advance(const Model& m, const Conditions& c, State& st, const StepPoint& p, D& drive,
                    R& record) {
  const double current_A = current_of(drive, st, p);
  if (!std::isfinite(current_A)) [[unlikely]]
    throw_not_finite(p.t_s, "coil current [A] from the drive", current_A);
  if constexpr (kQuasiStatic) {
    quasi_static_step_law<Law>(m, c, st, current_A);
  } else {
    step_law<Law>(m, c, st, {current_A, p.dt_s});
    st.t_s = p.t_s;
  }
  if (!std::isfinite(st.y_m)) [[unlikely]]
    throw_not_finite(p.t_s, "output y [m]", st.y_m);
  if (!std::isfinite(st.B_T)) [[unlikely]]
    throw_not_finite(p.t_s, "flux density B [T] of the induction coil", st.B_T);
  check_physical_validity(m, c, st, p.t_s);  // gmasim/model/validity.hpp (issue 19, item 3)
  record(std::as_const(st), p);
}
// The loop of run_loop() for one magnetisation law.
template <class Law, class D, class R>
void run_grid(const Model& m, const Conditions& c, State& st, const StepGrid& g, D& drive,
              R& record);

}  // namespace run_loop_detail

// Runs the grid from the state st (which it advances): for each step, the drive's current,
// step() (or quasi_static_step()), then the recorder. `c` is read at every step, so a
// recorder that owns the Conditions object may assign new conditions between steps
// (self-heating does). Throws DivergenceError (from step() or the checks above) with the
// steps before it recorded; allocation-free when the drive and the recorder are. The
// magnetisation law is dispatched here, once per run (step_law<Law> inside the loop).
template <StepDrive D, StepRecorder R>
void run_loop(const Model& m, const Conditions& c, State& st, const StepGrid& g, D&& drive,
              R&& record) {
  with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
    run_loop_detail::run_grid<decltype(law)>(m, c, st, g, drive, record);
  });
}

template <class Law, class D, class R>
void run_loop_detail::run_grid(const Model& m, const Conditions& c, State& st, const StepGrid& g,
                               D& drive, R& record) {
  StepPoint p;
  switch (g.clock) {
    case StepClock::Uniform:
      st.t_s = g.t0_s;
      p.dt_s = g.dt_s;
      for (long k = 1; k <= g.steps; ++k) {
        p.k = k;
        p.sample = k - 1;
        p.t_s = g.t0_s + static_cast<double>(k) * g.dt_s;
        run_loop_detail::advance<Law, false>(m, c, st, p, drive, record);
      }
      return;
    case StepClock::Spanning: {
      st.t_s = g.t0_s;
      double t_prev = g.t0_s;
      for (long k = 1; k <= g.steps; ++k) {
        p.k = k;
        p.sample = k - 1;
        p.t_s = k == g.steps ? g.t1_s : g.t0_s + static_cast<double>(k) * g.dt_s;
        p.dt_s = p.t_s - t_prev;
        t_prev = p.t_s;
        run_loop_detail::advance<Law, false>(m, c, st, p, drive, record);
      }
      return;
    }
    case StepClock::Sampled: {
      st.t_s = g.t0_s;
      p.dt_s = g.dt_s;
      const long samples = g.samples();
      for (long j = 0; j < samples; ++j) {
        const double t_sample = g.sample_time(j);
        p.sample = j;
        for (long q = 1; q <= g.substeps; ++q) {
          p.k = j * g.substeps + q;
          p.substep = q;
          p.t_s = t_sample + static_cast<double>(q) * g.dt_s;
          run_loop_detail::advance<Law, false>(m, c, st, p, drive, record);
        }
      }
      return;
    }
    case StepClock::QuasiStatic:
      for (long k = 1; k <= g.steps; ++k) {
        p.k = k;
        p.sample = k - 1;
        p.t_s = st.t_s;
        run_loop_detail::advance<Law, true>(m, c, st, p, drive, record);
      }
      return;
  }
}

// Step k (1, 2, ...) of a Uniform grid from t = 0 with the current held over the step: the
// loop's one step, with its checks and its time rule (State::t_s = k dt), for callers that
// are handed one current at a time: the sample-by-sample Stepper (gmasim/simulate/stepper.hpp, the
// C API, Python), which therefore judges divergence exactly as simulate() does.
inline void run_loop_step(const Model& m, const Conditions& c, State& st, long k, double dt_s,
                          double current_A) {
  StepPoint p;
  p.k = k;
  p.sample = k - 1;
  p.t_s = 0.0 + static_cast<double>(k) * dt_s;  // the Uniform clock's t0 + k dt with t0 = 0
  p.dt_s = dt_s;
  HeldCurrent drive{current_A};
  NoRecorder record;
  with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
    run_loop_detail::advance<decltype(law), false>(m, c, st, p, drive, record);
  });
}

// run_loop without a recorder.
template <StepDrive D>
void run_loop(const Model& m, const Conditions& c, State& st, const StepGrid& g, D&& drive) {
  run_loop(m, c, st, g, std::forward<D>(drive), NoRecorder{});
}

}  // namespace gmasim
