// The plant as a state space (gmasim linearize, issue 40 item 1): one linearisation at one
// temperature on the built-in model -- the bias settled (settle_at_bias), linearised and
// written as (A, B, C, D) -- and the PID loop's margins on it (track's table). Target: a
// linearisation in under 50 ms. Run: build/ci/bin/gmasim_bench --benchmark_filter=Linearize
#include <benchmark/benchmark.h>

#include "common.hpp"
#include "gmasim/experiments/experiments.hpp"

namespace {

using namespace gmasim;

void BM_LinearizePlant(benchmark::State& bs) {
  const double T = static_cast<double>(bs.range(0));
  for (auto _ : bs) benchmark::DoNotOptimize(linearize_plant(bench::mdma(), T, 1.0));
}
BENCHMARK(BM_LinearizePlant)->Arg(20)->Arg(70)->Unit(benchmark::kMillisecond);

void BM_LoopMargins(benchmark::State& bs) {
  const StateSpace plant = linearize_plant(bench::mdma(), 20.0, 1.0);
  for (auto _ : bs)
    benchmark::DoNotOptimize(pid_loop_margins(plant, PidGains{}, 10000.0, 10e-6, 0.5));
}
BENCHMARK(BM_LoopMargins)->Unit(benchmark::kMillisecond);

}  // namespace
