// Speed of the identification objective (issue 4, item 8): model evaluations per second of
// one 12-condition objective (20/45/70 degC x 6/8 A x 10/100 Hz, 2 periods each, 100
// samples per period), at the CI resolution (200 steps per period) and the default (500),
// on one thread and on two threads evaluating concurrently (as two islands do).
// The speed-up with MPI ranks: bench/identify_speedup.sh. Run: build/ci/bin/gmasim_bench
//   --benchmark_filter=Objective
#include <benchmark/benchmark.h>

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/simulate/lanes.hpp"

namespace {

using namespace gmasim;

const Objective& objective(int steps_per_period, bool lanes = true) {
  static std::mutex mu;
  static std::map<std::pair<int, bool>, std::unique_ptr<Objective>> cache;
  const std::lock_guard<std::mutex> lock(mu);
  auto& slot = cache[{steps_per_period, lanes}];
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
    s.lanes = lanes;
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
// The counters of a scalar / batched pair: evaluations per second, lanes, and the path.
void eval_counters(benchmark::State& bs, double evals, bool lanes, const std::string& what) {
  bs.SetItemsProcessed(static_cast<std::int64_t>(evals));
  bs.counters["evals_per_s"] = benchmark::Counter(evals, benchmark::Counter::kIsRate);
  bs.counters["simd_lanes"] = lanes ? lanes_width() : 1;
  bs.SetLabel(lanes ? what + "lanes on " + lanes_target() : "scalar step()");
}
// The same evaluation with its 12 records in SIMD lanes (batched) and one scalar run per
// record (scalar), side by side in one run: the items/s ratio is the lanes' speed-up.
void objective_evals(benchmark::State& bs, bool lanes) {
  const Objective& obj = objective(static_cast<int>(bs.range(0)), lanes);
  std::vector<double> u = obj.start_unit();
  u[0] = 0.4;
  for (auto _ : bs) benchmark::DoNotOptimize(obj.rms_pct(u));
  eval_counters(bs, static_cast<double>(bs.iterations()), lanes, "");
}
void BM_Objective12Conditions_scalar(benchmark::State& bs) { objective_evals(bs, false); }
void BM_Objective12Conditions_batched(benchmark::State& bs) { objective_evals(bs, true); }
BENCHMARK(BM_Objective12Conditions_scalar)->Arg(200)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Objective12Conditions_batched)->Arg(200)->Unit(benchmark::kMillisecond)->UseRealTime();

// A batch of 16 points, the central-difference columns of the 8 parameters around a point (what
// the refinement's Jacobian and the profile evaluate; a first population is a batch too):
// scalar, one residuals() per point on the scalar step; batched, one rms_pct_batch with the
// points' records in shared SIMD lanes, a vector holding one record across 8 points.
void objective_batch(benchmark::State& bs, bool lanes) {
  const Objective& obj = objective(static_cast<int>(bs.range(0)), lanes);
  std::vector<double> c = obj.start_unit();
  c[0] = 0.4;
  std::vector<std::vector<double>> u;
  for (std::size_t j = 0; j < c.size(); ++j)
    for (double h : {-1e-4, 1e-4}) {
      u.push_back(c);
      u.back()[j] += h;
    }
  for (auto _ : bs) {
    if (lanes) {
      benchmark::DoNotOptimize(obj.rms_pct_batch(u));
    } else {
      for (const auto& v : u) benchmark::DoNotOptimize(obj.rms_pct(v));
    }
  }
  eval_counters(bs, static_cast<double>(bs.iterations()) * static_cast<double>(u.size()), lanes,
                "16 points' records in ");
}
void BM_ObjectiveBatch16_scalar(benchmark::State& bs) { objective_batch(bs, false); }
void BM_ObjectiveBatch16_batched(benchmark::State& bs) { objective_batch(bs, true); }
BENCHMARK(BM_ObjectiveBatch16_scalar)->Arg(200)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ObjectiveBatch16_batched)->Arg(200)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK(BM_Objective12Conditions)
    ->Arg(200)
    ->Arg(500)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Threads(1)
    ->Threads(2);

}  // namespace
