// simulate_lanes's bookkeeping (gmasim/simulate/lanes.hpp) where a lane stops: a run that
// diverges mid-way reports what simulate() reports (its error, the steps it made, the rows it
// recorded), and the runs beside it go on; the recorded rows and the metrics windows follow the
// record's decimation (record_every) and start at the metrics window.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "gmasim/io/io.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace {

using namespace gmasim;

// A coil of 7.2e6 turns (as test_experiments' Sweep.DivergentPointIsReported): 6 mA drive it as
// 60 A would the MDMA's; 1000 A takes the field out of the physical range within the run.
std::vector<SimulationSettings> settings_with_a_stop() {
  std::vector<SimulationSettings> s;
  for (double pp : {6e-3, 1000.0, 4e-3, 8e-3}) {
    for (int every : {1, 3}) {
      SimulationSettings x;
      x.temperature_C = 20.0 + 10.0 * every;
      x.waveform = biased_sine(pp, 50.0, -3e-3);
      x.periods = 1.5;
      x.record_every = every;
      s.push_back(x);
    }
  }
  return s;
}

Model high_turns_model() {
  ModelSpec spec = builtin_model_spec();
  spec.set("circuit.branches.phi4.coil_turns", 7.2e6);
  return compile(spec);
}

TEST(LanesBookkeeping, AStoppedLaneReportsWhatSimulateReports) {
  const Model m = high_turns_model();
  const std::vector<SimulationSettings> s = settings_with_a_stop();
  for (bool metrics_only : {false, true}) {
    const std::vector<Result> got = simulate_lanes(m, s, metrics_only);
    ASSERT_EQ(got.size(), s.size());
    int stopped = 0;
    double worst = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const Result want = simulate(m, s[i]);
      EXPECT_EQ(got[i].diverged, want.diverged) << "setting " << i;
      EXPECT_EQ(got[i].error, want.error) << "setting " << i;
      EXPECT_EQ(got[i].steps, want.steps) << "setting " << i;
      stopped += got[i].diverged ? 1 : 0;
      if (got[i].diverged) {
        EXPECT_GT(got[i].steps, 0) << "the stop is mid-way: setting " << i;
      }
      if (!metrics_only) {
        EXPECT_EQ(got[i].series.rows(), want.series.rows()) << "setting " << i;
      }
      EXPECT_EQ(got[i].has_metrics, want.has_metrics) << "setting " << i;
      if (!got[i].has_metrics) continue;
      const double d = std::fabs(got[i].metrics.stroke_um - want.metrics.stroke_um);
      worst = std::max(worst, d / want.metrics.stroke_um);
      EXPECT_GT(want.metrics.stroke_um, 0.0);
    }
    EXPECT_EQ(stopped, 2);  // the 1000 A runs
    EXPECT_EQ(worst, 0.0);  // 0 since issue 38 (1.1e-15 before)
    std::printf("lanes vs simulate with a stopped lane (metrics_only %d): stroke %.3g relative\n",
                metrics_only ? 1 : 0, worst);
  }
}

}  // namespace
