// gmasim_step_count: the run of BM_FullModelStep/<0|1> (bench/bench_step.cpp), a fixed 2000
// steps of it (one 400 Hz period), for counting the instructions of step() under valgrind's
// callgrind (scripts/performance.py --step-budget, the ctest step_instruction_budget).
//
//   gmasim_step_count 0   the built-in model, consistent magnetic state
//   gmasim_step_count 1   the paper-as-printed reading (models/mdma_printed.toml)
//
// Why not gmasim_bench itself (issue 36): libhwy.so (Debian's 1.0.3), which the library links
// for its SIMD lanes, runs hwy::platform::TimerResolution() from its load-time constructor, and
// that probe executes RDTSCP, which valgrind 3.19 does not decode on every CPU ("unrecognised
// instruction" on AMD Zen 5): the program dies before main() and callgrind counts nothing. The
// constructor calls the probe through libhwy's PLT, so the definition below, in this
// executable, takes its place (the executable comes first in the dynamic linker's lookup):
// the constructor stores a resolution that only Highway's nanobenchmark reads, which nothing
// here calls, and neither step() nor this program runs any Highway code. The test
// step_count_replaces_highway_timer_probe checks that the dynamic linker binds the probe here.
// The steps are the same StepSequence of full_model_step_run (bench/step_fixture.hpp) as
// BM_FullModelStep's, and callgrind collects inside step() only, so the count is the
// benchmark's.
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "../step_fixture.hpp"

namespace hwy::platform {
// Replaces libhwy's load-time timer probe (see above); 1 tick, never read.
uint64_t TimerResolution();
uint64_t TimerResolution() { return 1; }
}  // namespace hwy::platform

int main(int argc, char** argv) {
  using namespace gmasim;
  if (argc != 2 || (std::strcmp(argv[1], "0") != 0 && std::strcmp(argv[1], "1") != 0)) {
    std::fprintf(stderr, "usage: gmasim_step_count 0|1 (0: built-in model, 1: printed reading)\n");
    return 2;
  }
  try {
    const bench::StepRun r = bench::full_model_step_run(argv[1][0] == '1');
    bench::StepSequence run(r.m, r.temperature_C, r.w, false);
    auto step_fn = bench::production_step;
    constexpr int kSteps = 2000;  // one 400 Hz period at the automatic dt of 1.25 us
    for (int k = 0; k < kSteps; ++k) run.next(step_fn);
    std::printf("gmasim_step_count %s: %d steps, y = %.9e m\n", argv[1], kSteps, run.state().y_m);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gmasim_step_count: %s\n", e.what());
    return 1;
  }
  return 0;
}
