// Speed of the identification objective (issue 4, item 8): model evaluations per second of
// one 12-condition objective (20/45/70 degC x 6/8 A x 10/100 Hz, 2 periods each, 100
// samples per period), at the CI resolution (200 steps per period) and the default (500),
// on one thread and on two threads evaluating concurrently (as two islands do).
// The speed-up with MPI ranks: bench/identify_speedup.sh. Run: build/ci/bin/gmasim_bench
//   --benchmark_filter=Objective
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <mutex>

#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"

namespace {

using namespace gmasim;

const Objective& objective(int steps_per_period) {
  static std::mutex mu;
  static std::map<int, std::unique_ptr<Objective>> cache;
  const std::lock_guard<std::mutex> lock(mu);
  auto& slot = cache[steps_per_period];
  if (!slot) {
    const Model truth = load_model("");
    SyntheticRequest r;  // the 12 conditions
    r.samples_per_period = 100;
    r.objective.steps_per_period = steps_per_period;
    const MeasurementSet data = synthesize_measurements(truth, r);
    const FitSpec fit = load_fit_spec(
        "rod1.ja.k0_A_per_m:1500:6000:log,rod1.ja.a0_A_per_m:3000:12000:log,rod1.ja.c0:0.01:0.3:"
        "log,"
        "rod1.ja.alpha0:-0.08:-0.005,rod1.k_j:0.3:3:log,material.beta_per_K:-4e-5:-2e-6:log,"
        "material.chi_m:8:50:log,rod1.damping_N_s_per_m:50:1500:log");
    ObjectiveSettings s;
    s.steps_per_period = steps_per_period;
    slot = std::make_unique<Objective>(builtin_model_spec(), data, fit, s);
  }
  return *slot;
}

// One full objective evaluation (12 simulations from rest, residuals) per iteration; the
// items/s counter is evaluations per second summed over the threads.
void BM_Objective12Conditions(benchmark::State& bs) {
  const Objective& obj = objective(static_cast<int>(bs.range(0)));
  std::vector<double> u = obj.start_unit();
  u[0] = 0.4 + 0.01 * bs.thread_index();  // not the truth, as in a search
  for (auto _ : bs) benchmark::DoNotOptimize(obj.rms_pct(u));
  bs.SetItemsProcessed(bs.iterations());
  bs.counters["steps_per_period"] =
      benchmark::Counter(static_cast<double>(bs.range(0)), benchmark::Counter::kAvgThreads);
}
BENCHMARK(BM_Objective12Conditions)
    ->Arg(200)
    ->Arg(500)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Threads(1)
    ->Threads(2);

}  // namespace
