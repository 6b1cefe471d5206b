// The run loop (gmasim/simulate/run_loop.hpp, issue 10): each clock of StepGrid against a
// hand-written loop with the same floating-point recipe (bit for bit: EXPECT_EQ on doubles), the
// loop's own checks (finite drive current and outputs) and the step limits of the grid factories,
// and that the loop with a no-op recorder allocates nothing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "builtin_models.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "gmasim/simulate/simulate.hpp"

using namespace gmasim;
using gmasim_test::g_allocations;
using gmasim_test::g_counting;
using ::testing::HasSubstr;

namespace {

using gmasim_test::mdma;

// What the recorders below keep of every step: its time and the state's outputs.
struct Trace {
  std::vector<double> t, I, y, B, H1;
  void add(const State& s) {
    t.push_back(s.t_s);
    I.push_back(s.current_A);
    y.push_back(s.y_m);
    B.push_back(s.B_T);
    H1.push_back(s.rods[0].H_A_per_m);
  }
};

// Every sample equal, bit for bit.
void expect_same(const Trace& ref, const Trace& loop) {
  ASSERT_EQ(ref.t.size(), loop.t.size());
  for (std::size_t k = 0; k < ref.t.size(); ++k) {
    EXPECT_EQ(ref.t[k], loop.t[k]) << "t at " << k;
    EXPECT_EQ(ref.I[k], loop.I[k]) << "I at " << k;
    EXPECT_EQ(ref.y[k], loop.y[k]) << "y at " << k;
    EXPECT_EQ(ref.B[k], loop.B[k]) << "B at " << k;
    EXPECT_EQ(ref.H1[k], loop.H1[k]) << "H at " << k;
  }
}

}  // namespace

// Uniform: t_k = t0 + k dt, step dt (simulate, the FRF, identify's sine targets). With
// t0 = 0 it is simulate()'s former t = k dt exactly (0 + x == x).
TEST(RunLoop, UniformClockIsTheHandWrittenLoopBitForBit) {
  const Model& m = mdma();
  const Conditions c = make_conditions(m, 70.0);
  const Waveform w = biased_sine(8.0, 100.0);
  const State s0 = make_state(m, c, w.current_at(0.0));
  for (const double t0 : {0.0, 0.0123}) {
    const double dt = w.period_s() / 2000.0;
    const long n = 3000;
    Trace ref, loop;
    State a = s0;
    a.t_s = t0;
    for (long k = 1; k <= n; ++k) {  // simulate()'s former loop, with its start time
      const double t = t0 == 0.0 ? static_cast<double>(k) * dt : t0 + static_cast<double>(k) * dt;
      step(m, c, a, {w.current_at(t), dt});
      a.t_s = t;
      ref.add(a);
    }
    State b = s0;
    run_loop(
        m, c, b, StepGrid::uniform(t0, dt, static_cast<double>(n), "test"),
        [&](double t) { return w.current_at(t); },
        [&](const State& s, const StepPoint&) { loop.add(s); });
    expect_same(ref, loop);
  }
}

// Spanning: the last step lands exactly on t1 and every step is t_k - t_{k-1} (identify's
// timed records, whose samples are interpolated between steps).
TEST(RunLoop, SpanningClockIsTheHandWrittenLoopBitForBit) {
  const Model& m = mdma();
  const Conditions c = make_conditions(m, 20.0);
  const Waveform w = biased_sine(6.0, 50.0);
  const double t0 = 0.013, t1 = 0.0613;
  const long n = 2992;
  const double dt = (t1 - t0) / static_cast<double>(n);
  // The option matters: the uniform recipe would not end on t1 here.
  ASSERT_NE(t0 + static_cast<double>(n) * dt, t1);
  const State s0 = make_state(m, c, w.current_at(t0));
  Trace ref, loop;
  State a = s0;
  a.t_s = t0;
  double t_prev = t0;
  for (long k = 1; k <= n; ++k) {  // record_run's former loop
    const double t = k == n ? t1 : t0 + static_cast<double>(k) * dt;
    step(m, c, a, {w.current_at(t), t - t_prev});
    a.t_s = t;
    t_prev = t;
    ref.add(a);
  }
  State b = s0;
  std::vector<double> lengths;
  const StepGrid g = StepGrid::spanning(t0, t1, static_cast<double>(n), "test");
  EXPECT_EQ(g.dt_s, dt);
  run_loop(
      m, c, b, g, [&](double t) { return w.current_at(t); },
      [&](const State& s, const StepPoint& p) {
        loop.add(s);
        lengths.push_back(p.dt_s);
      });
  expect_same(ref, loop);
  EXPECT_EQ(loop.t.back(), t1);
  EXPECT_EQ(lengths.back(), t1 - (t0 + static_cast<double>(n - 1) * dt));
}

// Sampled: a controller computes the current at each sample time t0 + j T_s from the state
// there and holds it for `substeps` steps ending at (t0 + j T_s) + q dt (track).
TEST(RunLoop, SampledClockIsTheHandWrittenLoopBitForBit) {
  const Model& m = mdma();
  const Conditions c = make_conditions(m, 45.0);
  const double Ts = 1.0 / 7000.0;
  const long sub = 13, samples = 300;
  const double dt = Ts / static_cast<double>(sub);
  // A proportional controller on y, so the held current depends on the sampled state.
  auto control = [](double tk, double y_m) {
    return 1.0 + 2.0 * std::sin(300.0 * tk) - 1e4 * (y_m - 30e-6);
  };
  const State s0 = make_state(m, c, 1.0);
  Trace ref, loop;
  std::vector<double> ref_tk, loop_tk;
  State a = s0;
  for (long k = 0; k < samples; ++k) {  // track's former loop
    const double tk = static_cast<double>(k) * Ts;
    const double I = control(tk, a.y_m);
    ref_tk.push_back(tk);
    for (long q = 1; q <= sub; ++q) {
      const double t = tk + static_cast<double>(q) * dt;
      step(m, c, a, {I, dt});
      a.t_s = t;
      ref.add(a);
    }
  }
  State b = s0;
  const StepGrid g = StepGrid::sampled(0.0, Ts, static_cast<double>(samples), sub, "test");
  EXPECT_EQ(g.steps, samples * sub);
  EXPECT_EQ(g.samples(), samples);
  double held = 0.0;
  run_loop(
      m, c, b, g,
      [&](const State& s, const StepPoint& p) {
        if (p.substep == 1) {
          const double tk = g.sample_time(p.sample);
          loop_tk.push_back(tk);
          held = control(tk, s.y_m);
        }
        return held;
      },
      [&](const State& s, const StepPoint&) { loop.add(s); });
  expect_same(ref, loop);
  EXPECT_EQ(ref_tk, loop_tk);
  // The option matters: a uniform clock of dt would place 1069 of the 3900 steps elsewhere.
  long moved = 0;
  for (std::size_t k = 0; k < loop.t.size(); ++k)
    moved += loop.t[k] != static_cast<double>(k + 1) * dt;
  EXPECT_EQ(moved, 1069);
}

// QuasiStatic: increments of quasi_static_step() to from + (to - from) k / n; time stays.
TEST(RunLoop, QuasiStaticClockIsTheHandWrittenLoopBitForBit) {
  const Model& m = mdma();
  const Conditions c = make_conditions(m, 20.0);
  const double from = -3.0, to = 5.0;
  const long n = 400;
  const State s0 = make_state(m, c, from);
  Trace ref, loop;
  State a = s0;
  for (long k = 1; k <= n; ++k) {  // record_run's former travel
    quasi_static_step(m, c, a,
                      from + (to - from) * static_cast<double>(k) / static_cast<double>(n));
    ref.add(a);
  }
  State b = s0;
  const StepGrid g = StepGrid::quasi_static(static_cast<double>(n), "test");
  run_loop(
      m, c, b, g,
      [&](const State&, const StepPoint& p) {
        return from + (to - from) * static_cast<double>(p.k) / static_cast<double>(g.steps);
      },
      [&](const State& s, const StepPoint& p) {
        loop.add(s);
        EXPECT_EQ(p.dt_s, 0.0);
      });
  expect_same(ref, loop);
  EXPECT_EQ(b.t_s, s0.t_s);
  EXPECT_EQ(b.current_A, to);
}

// The loop with a no-op recorder (and drives that allocate nothing) allocates nothing, on
// every clock.
TEST(RunLoop, NoOpRecorderAllocatesNothing) {
  const Model& m = mdma();
  const Conditions c = make_conditions(m, 70.0);
  const Waveform w = biased_sine(8.0, 200.0);
  State s = make_state(m, c, w.current_at(0.0));
  const StepGrid uniform = StepGrid::uniform(0.0, 1e-6, 5000.0, "test");
  const StepGrid spanning = StepGrid::spanning(0.005, 0.009, 3000.0, "test");
  const StepGrid sampled = StepGrid::sampled(0.009, 1e-4, 40.0, 10, "test");
  const StepGrid quasi = StepGrid::quasi_static(200.0, "test");
  auto sine = [&](double t) { return w.current_at(t); };
  step(m, c, s, {w.current_at(1e-6), 1e-6});  // warm-up
  g_allocations = 0;
  g_counting = true;
  run_loop(m, c, s, uniform, sine);
  run_loop(m, c, s, spanning, sine, NoRecorder{});
  run_loop(m, c, s, sampled, [](const State& x, const StepPoint&) { return 1.0 + 0.0 * x.y_m; });
  run_loop(m, c, s, quasi, [&](const State&, const StepPoint& p) { return 0.01 * p.k; });
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_TRUE(std::isfinite(s.y_m));
}

// A drive current that is not finite stops the loop at that step: the error names the step's
// time (exactly the grid's) and the quantity; the recorder holds every step before it.
TEST(RunLoop, NonFiniteDriveReportsTimeAndQuantityAndKeepsTheSamplesBefore) {
  const Model& m = mdma();
  const Conditions c = make_conditions(m, 20.0);
  State s = make_state(m, c, 0.0);
  const double t0 = 0.25, dt = 1e-5;
  const StepGrid g = StepGrid::uniform(t0, dt, 100.0, "test");
  std::vector<double> seen;
  try {
    run_loop(
        m, c, s, g,
        [&](double t) {
          return t >= t0 + 37 * dt ? std::numeric_limits<double>::quiet_NaN() : 1.0;
        },
        [&](const State& x, const StepPoint&) { seen.push_back(x.t_s); });
    FAIL() << "no DivergenceError";
  } catch (const DivergenceError& e) {
    EXPECT_EQ(e.time_s, t0 + 37 * dt);
    EXPECT_EQ(e.quantity, "coil current [A] from the drive");
    EXPECT_TRUE(std::isnan(e.value));
    EXPECT_THAT(e.what(), HasSubstr("not finite"));
  }
  ASSERT_EQ(seen.size(), 36u);
  for (std::size_t k = 0; k < seen.size(); ++k)
    EXPECT_EQ(seen[k], t0 + static_cast<double>(k + 1) * dt);
  EXPECT_EQ(s.t_s, seen.back());  // the state is that of the last recorded step
}

// An output that is not finite (here y, through a corrupted thermal expansion added to it)
// is caught after the step that produced it, which step() itself does not check.
TEST(RunLoop, NonFiniteOutputReportsTimeAndQuantity) {
  Model m = mdma();
  m.options.thermal_expansion_in_output = true;
  Conditions c = make_conditions(m, 20.0);
  State s = make_state(m, c, 0.0);
  std::vector<double> seen;
  auto drive = [](double) { return 1.0; };
  auto rec = [&](const State& x, const StepPoint&) { seen.push_back(x.y_m); };
  run_loop(m, c, s, StepGrid::uniform(0.0, 1e-5, 10.0, "test"), drive, rec);
  c.thermal_expansion_m = std::numeric_limits<double>::quiet_NaN();
  try {
    run_loop(m, c, s, StepGrid::uniform(1e-4, 1e-5, 10.0, "test"), drive, rec);
    FAIL() << "no DivergenceError";
  } catch (const DivergenceError& e) {
    EXPECT_EQ(e.time_s, 1e-4 + 1e-5);
    EXPECT_EQ(e.quantity, "output y [m]");
  }
  EXPECT_EQ(seen.size(), 10u);
}

// A divergence inside step() (a current far beyond any coil's) carries step()'s own report:
// time, rod and quantity; the recorder holds the steps before it.
TEST(RunLoop, DivergenceInsideStepKeepsTheSamplesBefore) {
  const Model& m = mdma();
  const Conditions c = make_conditions(m, 20.0);
  State s = make_state(m, c, 0.0);
  const double dt = 1e-5;
  std::vector<double> seen;
  try {
    run_loop(
        m, c, s, StepGrid::uniform(0.0, dt, 100.0, "test"),
        [&](double t) { return t > 20.5 * dt ? 1e12 : 1.0; },
        [&](const State& x, const StepPoint&) { seen.push_back(x.t_s); });
    FAIL() << "no DivergenceError";
  } catch (const DivergenceError& e) {
    EXPECT_NEAR(e.time_s, 21 * dt, 1e-15);
    EXPECT_FALSE(e.quantity.empty());
  }
  EXPECT_EQ(seen.size(), 20u);
}

// The step limits live in the grid factories (kMaxSteps = 2e8) and in steps_to_resolve.
TEST(RunLoop, GridFactoriesApplyTheStepLimit) {
  auto message = [](auto f) {
    try {
      f();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message([] { (void)StepGrid::uniform(0.0, 1e-5, 3e8, "run x"); }),
              HasSubstr("run x = 3e+08: too many (limit 2e+08)"));
  EXPECT_THAT(message([] { (void)StepGrid::sampled(0.0, 1e-4, 2e7, 11, "track y"); }),
              HasSubstr("track y = 2.2e+08: too many (limit 2e+08)"));
  EXPECT_THAT(message([] { (void)StepGrid::sampled(0.0, 1e-4, 10.0, 0, "track y"); }),
              HasSubstr("must be >= 1"));
  // Samples are rounded first, then counted with their steps: the checked count is the run's.
  EXPECT_THAT(message([] { (void)StepGrid::sampled(0.0, 1e-4, 3e8, 1, "trk"); }),
              HasSubstr("trk: samples = 3e+08: too many (limit 2e+08)"));
  EXPECT_THAT(message([] { (void)StepGrid::sampled(0.0, 1e-4, 0.3, 5, "trk"); }),
              HasSubstr("trk: 0.3 samples: need at least 1"));
  EXPECT_EQ(StepGrid::sampled(0.0, 1e-4, 10.4, 3, "x").steps, 30);
  EXPECT_EQ(StepGrid::sampled(0.0, 1e-4, 10.6, 3, "x").steps, 33);
  EXPECT_THAT(message([] { (void)StepGrid::sampled(0.0, 1e-4, 2e8 / 4 + 0.6, 4, "trk"); }),
              HasSubstr("trk = 2e+08: too many") /* 50000001 samples x 4 */);
  EXPECT_THAT(message([] { (void)StepGrid::quasi_static(1e300, "qs"); }),
              HasSubstr("qs = 1e+300: too many"));
  EXPECT_THAT(message([] { (void)StepGrid::covering(0.0, 1e300, 1e-5, "simulation"); }),
              HasSubstr("simulation: 1e+305 steps of 1e-05 s over 1e+300 s: too many"));
  EXPECT_THAT(message([] { (void)StepGrid::uniform(0.0, 0.0, 10.0, "z"); }),
              HasSubstr("z: time step 0 s: must be finite and > 0"));
  EXPECT_THAT(message([] { (void)steps_to_resolve(1e20, 1, "steps per period"); }),
              HasSubstr("steps per period = 1e+20: too many"));
  // ceil with a 1e-9 tolerance, at least at_least.
  EXPECT_EQ(steps_to_resolve(2.0 + 1e-12, 1, "x"), 2);
  EXPECT_EQ(steps_to_resolve(2.0 + 1e-6, 1, "x"), 3);
  EXPECT_EQ(steps_to_resolve(0.5, 8, "x"), 8);
  // covering: the nearest whole step, at least one.
  EXPECT_EQ(StepGrid::covering(0.0, 0.30000000000000004, 0.1, "x").steps, 3);
  EXPECT_EQ(StepGrid::covering(0.0, 0.01, 1.0, "x").steps, 1);
}
