// Speed of the model step (issue 2): ns per full step, one converged period at 10 Hz and
// 400 Hz (8 A, 70 degC) with the exact-update step, and the same periods with a plain
// explicit RK4 at 2 us as the reference. Run: build/ci/bin/gmasim_bench
#include <benchmark/benchmark.h>

#include <cmath>

#include "common.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace {

using namespace gmasim;

using bench::mdma;

// One step of the built-in model (consistent magnetic state: a Newton solve on the rods'
// fields) or, with Arg(1), of the printed reading.
// Its instructions per step are counted by gmasim_step_count (bench/count: the same run, a fixed
// 2000 steps, under callgrind; scripts/performance.py --sections callgrind).
void BM_FullModelStep(benchmark::State& bs) {
  const bench::StepRun r = bench::full_model_step_run(bs.range(0) == 1);
  bench::step_loop(bs, r.m, r.temperature_C, r.w);
}
BENCHMARK(BM_FullModelStep)->Arg(0)->Arg(1);

// The same step of the built-in model with the energy ledgers booked (gmasim/model/energy.hpp:
// every branch of the circuit solved, each rod's dissipation along the step's path and its
// oscillator's power by Gauss-Legendre), against BM_FullModelStep/0 (issue 18).
void BM_FullModelStepWithLedger(benchmark::State& bs) {
  const bench::StepRun r = bench::full_model_step_run(false);
  bench::step_loop(bs, r.m, r.temperature_C, r.w, true);
}
BENCHMARK(BM_FullModelStepWithLedger);

// One period of the biased sine with the production step at the automatic dt (the step
// the convergence test validates to 0.1 %).
void BM_PeriodExact(benchmark::State& bs) {
  const double f = static_cast<double>(bs.range(0));
  const Model& m = mdma();
  const Conditions c = make_conditions(m, 70.0);
  const Waveform w = biased_sine(8.0, f);
  const double dt = auto_dt(w);
  const long n = std::lround(w.period_s() / dt);
  State s0 = make_state(m, c, w.current_at(0.0));
  for (auto _ : bs) {
    State s = s0;
    for (long k = 1; k <= n; ++k) step(m, c, s, {w.current_at(static_cast<double>(k) * dt), dt});
    benchmark::DoNotOptimize(s.y_m);
  }
  bs.counters["steps"] = static_cast<double>(n);
  bs.counters["dt_us"] = dt * 1e6;
}
BENCHMARK(BM_PeriodExact)->Arg(10)->Arg(400)->Unit(benchmark::kMillisecond);

// The same period with the plain explicit RK4 at 2 us (the printed reading: the RK4
// reference has no counterpart of the consistent state's Newton solve).
void BM_PeriodRk4At2us(benchmark::State& bs) {
  const double f = static_cast<double>(bs.range(0));
  const Model& m = bench::mdma_printed();
  const Conditions c = make_conditions(m, 70.0);
  const Waveform w = biased_sine(8.0, f);
  const double dt = 2e-6;
  const long n = std::lround(w.period_s() / dt);
  State s0 = make_state(m, c, w.current_at(0.0));
  for (auto _ : bs) {
    State s = s0;
    for (long k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) * dt;
      rk4_reference_step(m, c, s, w.current_at(t), w.current_at(t + 0.5 * dt), w.current_at(t + dt),
                         dt);
    }
    benchmark::DoNotOptimize(s.y_m);
  }
  bs.counters["steps"] = static_cast<double>(n);
}
BENCHMARK(BM_PeriodRk4At2us)->Arg(10)->Arg(400)->Unit(benchmark::kMillisecond);

}  // namespace
