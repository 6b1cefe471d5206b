// The step benchmarks' fixed sequence of steps, without Google Benchmark, so that both
// gmasim_bench (common.hpp's step_loop) and the callgrind counter gmasim_step_count
// (bench/count/step_count.cpp) take exactly the same steps: m at temperature_C from make_state
// at the waveform's t = 0, step k at t = k * dt with the waveform's automatic dt.
#pragma once

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

// One run of steps; next() takes step k = 1, 2, ... through step_fn(m, c, s, in).
class StepSequence {
 public:
  StepSequence(const Model& m, double temperature_C, const Waveform& w, bool ledger)
      : m_(m),
        c_(make_conditions(m, temperature_C)),
        s_(make_state(m, c_, w.current_at(0.0))),
        w_(w),
        dt_s_(auto_dt(w)) {
    s_.energy.enabled = ledger;
  }
  template <class StepFn>
  void next(StepFn& step_fn) {
    ++k_;
    step_fn(m_, c_, s_, StepInput{w_.current_at(static_cast<double>(k_) * dt_s_), dt_s_});
  }
  const State& state() const { return s_; }

 private:
  const Model& m_;
  Conditions c_;
  State s_;
  Waveform w_;
  double dt_s_;
  long k_ = 0;
};

// BM_FullModelStep's run, which gmasim_step_count counts: the built-in model (consistent
// magnetic state) or, printed, the paper-as-printed reading, at 70 degC under the 8 A p-p
// biased sine at 400 Hz (automatic dt 1.25 us: 2000 steps a period).
struct StepRun {
  const Model& m;
  double temperature_C;
  Waveform w;
};
inline StepRun full_model_step_run(bool printed) {
  return {printed ? mdma_printed() : mdma(), 70.0, biased_sine(8.0, 400.0)};
}

// The production step, as step_fn.
inline void production_step(const Model& m, const Conditions& c, State& s, const StepInput& in) {
  step(m, c, s, in);
}

}  // namespace gmasim::bench
