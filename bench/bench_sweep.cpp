// Sweep throughput (issue: `gmasim sweep`): points per second for the default grid,
// 20-70 degC in 10 degC steps x 6/8/10/12 A x 10 Hz (24 points, 3 periods each), with 1
// and 2 worker threads. Real (wall) time, since the work runs on worker threads.
// Run: build/ci/bin/gmasim_bench --benchmark_filter=Sweep
#include <benchmark/benchmark.h>

#include "common.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/io/io.hpp"

namespace {

using namespace gmasim;

using bench::mdma;

void BM_SweepDefaultGrid(benchmark::State& bs) {
  const Model& m = mdma();
  SweepRequest r;  // the default grid
  r.threads = static_cast<int>(bs.range(0));
  std::size_t points = 0;
  long steps = 0;
  for (auto _ : bs) {
    const SweepResult res = run_sweep(m, r);
    points += res.points.size();
    benchmark::DoNotOptimize(res.points.back().metrics.stroke_um);
  }
  // 10 Hz at the automatic dt (10 us): 3 periods = 30000 steps per point.
  steps = static_cast<long>(3 * 0.1 / 10e-6);
  bs.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
  bs.counters["points"] = static_cast<double>(points) / static_cast<double>(bs.iterations());
  bs.counters["steps_per_point"] = static_cast<double>(steps);
  bs.counters["threads"] = static_cast<double>(r.threads);
}
BENCHMARK(BM_SweepDefaultGrid)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(3)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
