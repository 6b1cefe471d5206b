// Cost of the C API (issue 9): ns per gmasim_sim_step, the same step as BM_FullModelStep/0
// (built-in model, 70 degC, 8 A 400 Hz biased sine, automatic dt) behind the C boundary
// (argument checks, the divergence latch, exception guard), and a step plus the bulk
// gmasim_sim_outputs read a real-time loop would do. Run: build/ci/bin/gmasim_bench
//   --benchmark_filter=CApi
#include <benchmark/benchmark.h>

#include "gmasim/capi/gmasim_c.h"
#include "gmasim/simulate/simulate.hpp"

namespace {

void BM_CApiSimStep(benchmark::State& bs) {
  gmasim_model* m = nullptr;
  gmasim_sim* s = nullptr;
  const gmasim::Waveform w = gmasim::biased_sine(8.0, 400.0);
  const double dt = gmasim::auto_dt(w);
  if (gmasim_model_load(nullptr, &m) != GMASIM_OK ||
      gmasim_sim_create(m, 70.0, dt, w.current_at(0.0), &s) != GMASIM_OK) {
    bs.SkipWithError(gmasim_last_error());
    gmasim_model_free(m);
    return;
  }
  const bool read_outputs = bs.range(0) != 0;
  gmasim_outputs out;
  long k = 0;
  for (auto _ : bs) {
    ++k;
    if (gmasim_sim_step(s, w.current_at(static_cast<double>(k) * dt)) != GMASIM_OK) {
      bs.SkipWithError(gmasim_sim_last_error(s));
      break;
    }
    if (read_outputs) gmasim_sim_outputs(s, &out);
    benchmark::DoNotOptimize(out);
  }
  gmasim_sim_free(s);
  gmasim_model_free(m);
}
BENCHMARK(BM_CApiSimStep)->Arg(0)->Arg(1);

}  // namespace
