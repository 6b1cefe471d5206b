// The magnetisation-law seam (issue 21): the built-in model's step through the public step()
// (one branch on the law per call) against step_law<JilesAthertonLaw> (the step compiled for
// the law, as run_loop() calls it: the law dispatched once per run), and the single-rod
// template with each law (models/single_rod.toml, models/single_rod_preisach.toml), measured in
// the same run. Run: build/ci/bin/gmasim_bench --benchmark_filter=Law
#include <benchmark/benchmark.h>

#include <cmath>
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
  const Waveform w = biased_sine(8.0, 400.0);
  if (bs.range(0) == 0)
    bench::step_loop(bs, bench::mdma(), 70.0, w);
  else
    bench::step_loop(bs, bench::mdma(), 70.0, w, false,
                     [](const Model& m, const Conditions& c, State& s, const StepInput& in) {
                       step_law<JilesAthertonLaw>(m, c, s, in);
                     });
}
BENCHMARK(BM_LawSeamJaStep)->Arg(0)->Arg(1)->Arg(0)->Arg(1);

// The cost of the seam itself (issue 21: JA's step cost within 3 % of before): one move of the
// Jiles-Atherton law as the consistent step's Newton solve makes it, Arg(0) by the physics
// function the step called before the seam (physics::ja_step_from with the rod's constants),
// Arg(1) through the seam (JilesAthertonLaw::begin_move + trial_from), on the same sequence of
// fields (rod 0 of the built-in model at 70 degC, a 2 kA/m sine of 64 steps around its bias).
// Both are inline: the same instructions are expected, so the same time (interleaved).
void BM_LawSeamJaMove(benchmark::State& bs) {
  const Model& m = bench::mdma();
  const Conditions c = make_conditions(m, 70.0);
  const State s0 = make_state(m, c, 8.0);
  const RodConditions& rc = c.rods[0];
  RodState r = s0.rods[0];
  const double H0 = r.H_A_per_m;
  long k = 0;
  double acc = 0.0;
  for (auto _ : bs) {
    const double H1 = H0 + 2000.0 * std::sin(0.09817477042468103 * static_cast<double>(++k));
    double M = 0.0, dM_dH = 0.0;
    if (bs.range(0) == 0) {
      double Mirr = 0.0, chi_e = 0.0;
      const auto st = physics::ja_move_start(r.H_A_per_m, r.M_A_per_m, rc.MsT_mag, rc.ja);
      physics::ja_step_from(r.H_A_per_m, st, H1, rc.MsT_mag, rc.ja, r.Mirr_A_per_m, r.M_A_per_m,
                            r.M_A_per_m, Mirr, M, chi_e);
      dM_dH = physics::ja_slope(chi_e, rc.ja);
    } else {
      const auto t =
          JilesAthertonLaw::trial_from(rc, r, JilesAthertonLaw::begin_move(rc, r), H1, r.M_A_per_m);
      M = t.M;
      dM_dH = t.dM_dH;
    }
    acc += M + dM_dH;
    benchmark::DoNotOptimize(acc);
  }
}
BENCHMARK(BM_LawSeamJaMove)->Arg(0)->Arg(1)->Arg(0)->Arg(1)->Arg(0)->Arg(1);

// One step of the single-rod template: Arg(0) Jiles-Atherton, Arg(1) Preisach (8 A, 50 Hz).
void BM_LawSingleRodStep(benchmark::State& bs) {
  bench::step_loop(bs, single_rod(bs.range(0) == 1), 20.0, biased_sine(8.0, 50.0));
}
BENCHMARK(BM_LawSingleRodStep)->Arg(0)->Arg(1);

}  // namespace
