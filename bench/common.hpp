// Shared pieces of the benchmarks.
#pragma once

#include <benchmark/benchmark.h>

#include "step_fixture.hpp"

namespace gmasim::bench {

// The step benchmarks' loop: one StepSequence::next per iteration (step_fixture.hpp), step()
// by default, with the energy ledgers booked if `ledger`.
template <class StepFn>
void step_loop(benchmark::State& bs, const Model& m, double temperature_C, const Waveform& w,
               bool ledger, StepFn step_fn) {
  StepSequence run(m, temperature_C, w, ledger);
  for (auto _ : bs) {
    run.next(step_fn);
    benchmark::DoNotOptimize(run.state().y_m);
  }
}
inline void step_loop(benchmark::State& bs, const Model& m, double temperature_C, const Waveform& w,
                      bool ledger = false) {
  step_loop(bs, m, temperature_C, w, ledger, production_step);
}

}  // namespace gmasim::bench
