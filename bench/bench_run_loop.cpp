// Overhead of the run loop (gmasim/simulate/run_loop.hpp, issue 10) over a hand-written step loop:
// one period of the 400 Hz biased sine (2000 steps, 70 degC) on the built-in model, with the
// same drive; the loop adds the finiteness checks of the current and the outputs and the call
// of a (no-op, or recording) recorder. Run: build/ci/bin/gmasim_bench --benchmark_filter=Loop
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "common.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace {

using namespace gmasim;

struct Setup {
  const Model& m = bench::mdma();
  Conditions c = make_conditions(m, 70.0);
  Waveform w = biased_sine(8.0, 400.0);
  double dt = auto_dt(w);
  long n = std::lround(w.period_s() / dt);
  State s0 = make_state(m, c, w.current_at(0.0));
};

// The loop simulate() had before issue 10: t = k dt, step, t_s = t.
void BM_RawStepLoop(benchmark::State& bs) {
  const Setup x;
  for (auto _ : bs) {
    State s = x.s0;
    for (long k = 1; k <= x.n; ++k) {
      const double t = static_cast<double>(k) * x.dt;
      step(x.m, x.c, s, {x.w.current_at(t), x.dt});
      s.t_s = t;
    }
    benchmark::DoNotOptimize(s.y_m);
  }
  bs.counters["per_step"] =
      benchmark::Counter(static_cast<double>(x.n), benchmark::Counter::kIsIterationInvariantRate |
                                                       benchmark::Counter::kInvert);
}
BENCHMARK(BM_RawStepLoop)->Unit(benchmark::kMicrosecond);

// The same period through run_loop with a no-op recorder.
void BM_RunLoopNoRecorder(benchmark::State& bs) {
  const Setup x;
  const StepGrid g = StepGrid::uniform(0.0, x.dt, static_cast<double>(x.n), "bench");
  for (auto _ : bs) {
    State s = x.s0;
    run_loop(x.m, x.c, s, g, [&x](double t) { return x.w.current_at(t); });
    benchmark::DoNotOptimize(s.y_m);
  }
  bs.counters["per_step"] =
      benchmark::Counter(static_cast<double>(x.n), benchmark::Counter::kIsIterationInvariantRate |
                                                       benchmark::Counter::kInvert);
}
BENCHMARK(BM_RunLoopNoRecorder)->Unit(benchmark::kMicrosecond);

// The same period recording y and B into preallocated buffers (what identify's targets do).
void BM_RunLoopRecording(benchmark::State& bs) {
  const Setup x;
  const StepGrid g = StepGrid::uniform(0.0, x.dt, static_cast<double>(x.n), "bench");
  std::vector<double> y(static_cast<std::size_t>(x.n) + 1), B(y.size());
  for (auto _ : bs) {
    State s = x.s0;
    run_loop(
        x.m, x.c, s, g, [&x](double t) { return x.w.current_at(t); },
        [&](const State& st, const StepPoint& p) {
          y[static_cast<std::size_t>(p.k)] = st.y_m;
          B[static_cast<std::size_t>(p.k)] = st.B_T;
        });
    benchmark::DoNotOptimize(y.data());
  }
  bs.counters["per_step"] =
      benchmark::Counter(static_cast<double>(x.n), benchmark::Counter::kIsIterationInvariantRate |
                                                       benchmark::Counter::kInvert);
}
BENCHMARK(BM_RunLoopRecording)->Unit(benchmark::kMicrosecond);

}  // namespace
