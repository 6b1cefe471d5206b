// Sweep throughput of the Preisach model (models/single_rod_preisach.toml; docs/lanes.md,
// "Preisach lanes"): points per second of a sweep of 8 points -- 20-80 degC x 2/4 A at the default
// sweep's 10 Hz, one AVX-512 vector of lanes -- 1 period each (the automatic dt, 10 us: 10000
// steps), scalar (one simulate() per point) and batched (the Preisach lanes), on one thread. The
// rest states (make_state) are scalar on both paths. Real (wall) time.
// Run: build/release/bin/gmasim_bench --benchmark_filter=PreisachSweep
#include <benchmark/benchmark.h>

#include <string>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/simulate/lanes.hpp"

namespace {

using namespace gmasim;

const Model& preisach_model() {
  static const Model m =
      load_model(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod_preisach.toml");
  return m;
}

void preisach_sweep(benchmark::State& bs, bool lanes) {
  SweepRequest r;
  r.temperatures_C = {20, 40, 60, 80};
  r.currents_pp_A = {2, 4};
  r.frequencies_Hz = {10};
  r.periods = 1;
  r.threads = 1;
  r.lanes = lanes;
  std::size_t points = 0;
  for (auto _ : bs) {
    const SweepResult res = run_sweep(preisach_model(), r);
    points += res.points.size();
    benchmark::DoNotOptimize(res.points.back().metrics.stroke_um);
  }
  bs.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
  bs.counters["simd_lanes"] = lanes ? lanes_width() : 1;
  bs.SetLabel(lanes ? "Preisach lanes on " + lanes_target() : "scalar step()");
}

void BM_PreisachSweep_scalar(benchmark::State& bs) { preisach_sweep(bs, false); }
void BM_PreisachSweep_batched(benchmark::State& bs) { preisach_sweep(bs, true); }
BENCHMARK(BM_PreisachSweep_scalar)->Iterations(3)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PreisachSweep_batched)->Iterations(3)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
