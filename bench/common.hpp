// Shared pieces of the benchmarks.
#pragma once

#include <benchmark/benchmark.h>

#include <string>

#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim::bench {

// The built-in MDMA model, loaded once.
inline const Model& mdma() {
  static const Model m = load_model("");
  return m;
}

// The paper-as-printed reading (models/mdma_printed.toml): the RK4 reference needs it.
inline const Model& mdma_printed() {
  static const Model m = load_model(std::string(GMASIM_SOURCE_DIR) + "/models/mdma_printed.toml");
  return m;
}

// The step benchmarks' loop: m at temperature_C from make_state at the waveform's t = 0, with
// the energy ledgers booked if `ledger`; one step_fn(m, c, s, in) per iteration at the
// waveform's automatic dt (step() by default).
template <class StepFn>
void step_loop(benchmark::State& bs, const Model& m, double temperature_C, const Waveform& w,
               bool ledger, StepFn step_fn) {
  const Conditions c = make_conditions(m, temperature_C);
  State s = make_state(m, c, w.current_at(0.0));
  s.energy.enabled = ledger;
  const double dt = auto_dt(w);
  long k = 0;
  for (auto _ : bs) {
    ++k;
    step_fn(m, c, s, StepInput{w.current_at(static_cast<double>(k) * dt), dt});
    benchmark::DoNotOptimize(s.y_m);
  }
}
inline void step_loop(benchmark::State& bs, const Model& m, double temperature_C, const Waveform& w,
                      bool ledger = false) {
  step_loop(bs, m, temperature_C, w, ledger,
            [](const Model& mm, const Conditions& c, State& s, const StepInput& in) {
              step(mm, c, s, in);
            });
}

}  // namespace gmasim::bench
