// Cost of building a model (issue 10): compile() of the built-in spec, which lands every
// number by the parameter table after checking it against its row (identify compiles once
// per evaluation), and make_conditions() at one temperature (self-heating recomputes it every
// thermal step). Run: build/ci/bin/gmasim_bench --benchmark_filter='Compile|Conditions'
#include <benchmark/benchmark.h>

#include "common.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"

namespace {

using namespace gmasim;

void BM_CompileBuiltIn(benchmark::State& bs) {
  const ModelSpec spec = builtin_model_spec();
  for (auto _ : bs) {
    Model m = compile(spec);
    benchmark::DoNotOptimize(m.rods.data());
  }
}
BENCHMARK(BM_CompileBuiltIn);

// The identify path: one number changed by ModelSpec::set (its rules and the cross rules
// that depend on it), then compile.
void BM_SetAndCompile(benchmark::State& bs) {
  ModelSpec spec = builtin_model_spec();
  double k0 = 3000.0;
  for (auto _ : bs) {
    k0 = k0 == 3000.0 ? 3100.0 : 3000.0;
    spec.set("rod2.ja.k0_A_per_m", k0);
    Model m = compile(spec);
    benchmark::DoNotOptimize(m.rods.data());
  }
}
BENCHMARK(BM_SetAndCompile);

void BM_MakeConditions(benchmark::State& bs) {
  const Model& m = bench::mdma();
  double T = 70.0;
  for (auto _ : bs) {
    T = T == 70.0 ? 71.0 : 70.0;
    Conditions c = make_conditions(m, T);
    benchmark::DoNotOptimize(c.rods.data());
  }
}
BENCHMARK(BM_MakeConditions);

}  // namespace
