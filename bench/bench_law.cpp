// The magnetisation-law seam (issue 21): the built-in model's step through the public step()
// (one branch on the law per call) against step_law<JilesAthertonLaw> (the step compiled for
// the law, as run_loop() calls it: the law dispatched once per run), and the single-rod
// template with each law (models/single_rod.toml, models/single_rod_preisach.toml), measured in
// the same run. Run: build/ci/bin/gmasim_bench --benchmark_filter=Law
#include <benchmark/benchmark.h>

#include <string>

#include "common.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace {

using namespace gmasim;

const Model& single_rod(bool preisach) {
  static const Model ja = load_model(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod.toml");
  static const Model pr =
      load_model(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod_preisach.toml");
  return preisach ? pr : ja;
}

// Arg(0): step(); Arg(1): step_law<JilesAthertonLaw> (the built-in model, 8 A, 400 Hz, 70 degC).
void BM_LawSeamJaStep(benchmark::State& bs) {
  const Model& m = bench::mdma();
  const Conditions c = make_conditions(m, 70.0);
  const Waveform w = biased_sine(8.0, 400.0);
  State s = make_state(m, c, w.current_at(0.0));
  const double dt = auto_dt(w);
  long k = 0;
  for (auto _ : bs) {
    ++k;
    const StepInput in{w.current_at(static_cast<double>(k) * dt), dt};
    if (bs.range(0) == 0)
      step(m, c, s, in);
    else
      step_law<JilesAthertonLaw>(m, c, s, in);
    benchmark::DoNotOptimize(s.y_m);
  }
}
BENCHMARK(BM_LawSeamJaStep)->Arg(0)->Arg(1)->Arg(0)->Arg(1);

// One step of the single-rod template: Arg(0) Jiles-Atherton, Arg(1) Preisach (8 A, 50 Hz).
void BM_LawSingleRodStep(benchmark::State& bs) {
  const Model& m = single_rod(bs.range(0) == 1);
  const Conditions c = make_conditions(m, 20.0);
  const Waveform w = biased_sine(8.0, 50.0);
  State s = make_state(m, c, w.current_at(0.0));
  const double dt = auto_dt(w);
  long k = 0;
  for (auto _ : bs) {
    ++k;
    step(m, c, s, {w.current_at(static_cast<double>(k) * dt), dt});
    benchmark::DoNotOptimize(s.y_m);
  }
}
BENCHMARK(BM_LawSingleRodStep)->Arg(0)->Arg(1);

}  // namespace
