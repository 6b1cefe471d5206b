// Real-time cost of the inverse-model feed-forward (gmasim/experiments/feedforward.hpp, issue 20):
// one controller sample (the polynomial preview filter and the quasi-static inverse on the shadow
// state) while tracking a 20 um, 100 Hz sine at 10 kHz, 20 and 70 degC, on the built-in model.
// The budget of a 10 kHz controller is 100 us per sample. The counters report the quasi-static
// steps per sample. Run: build/ci/bin/gmasim_bench --benchmark_filter=Feedforward
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>

#include "common.hpp"
#include "gmasim/experiments/feedforward.hpp"
#include "gmasim/model/model.hpp"

namespace {

using namespace gmasim;

void BM_FeedforwardSample(benchmark::State& bs) {
  const double T = static_cast<double>(bs.range(0));
  InverseFeedforward ff(bench::mdma(), T, {});
  const double w = 2.0 * 3.141592653589793 * 100.0, A = 20.0, Ts = 1e-4;
  long k = 0, evaluations = 0;
  for (auto _ : bs) {
    const double t = (static_cast<double>(k % 100) + 0.5) * Ts;  // one period, repeated
    const double s = A * std::sin(w * t), c = A * std::cos(w * t);
    benchmark::DoNotOptimize(ff.current_A({s, w * c, -w * w * s, -w * w * w * c}));
    evaluations += ff.last_evaluations();
    ++k;
  }
  bs.counters["qs_steps_per_sample"] =
      static_cast<double>(evaluations) / static_cast<double>(std::max(k, 1L));
}
BENCHMARK(BM_FeedforwardSample)->Arg(20)->Arg(70)->Unit(benchmark::kMicrosecond);

}  // namespace
