// The describing function beside the state space (issue 40 item 1, gmasim linearize
// --amplitude): at a vanishing amplitude it is the small-signal response; at 1 A it is the FRF's
// large-signal stepped sine (the same machinery, gmasim frf --amplitude 1).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "builtin_models.hpp"
#include "experiments_fixtures.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/mechanics/state_space.hpp"
#include "test_util.hpp"

using gmasim::describing_function;
using gmasim::FrfCurve;
using gmasim::FrfRequest;
using gmasim::FrfResult;
using gmasim::linearize_plant;
using gmasim::Model;
using gmasim::run_frf;
using gmasim::StateSpace;

TEST(DescribingFunction, IsTheSmallSignalResponseAtAVanishingAmplitude) {
  const Model& m = gmasim_test::mdma();
  const StateSpace ss = linearize_plant(m, 20.0, 1.0);
  const auto df = describing_function(m, ss, 1e-5, {10.0, 100.0, 1000.0}, 2);
  ASSERT_EQ(df.size(), 3u);
  double worst_mag = 0.0, worst_deg = 0.0;
  for (const auto& p : df) {
    worst_mag = std::max(worst_mag, std::fabs(p.gain_um_per_A / p.small_signal_gain_um_per_A - 1));
    worst_deg = std::max(worst_deg, std::fabs(p.phase_deg - p.small_signal_phase_deg));
  }
  std::printf("10 uA describing function vs small signal: %.3g relative, %.3g deg\n", worst_mag,
              worst_deg);
  EXPECT_LT(worst_mag,
            5e-4);  // observed 4.6e-5 (the JA law's irreversible part, linear in the amplitude)
  EXPECT_LT(worst_deg, 0.02);  // observed 0.0019 deg
}

TEST(DescribingFunction, AtOneAmpereIsTheFrfsLargeSignalSteppedSine) {
  const Model& m = gmasim_test::mdma();
  const StateSpace ss = linearize_plant(m, 20.0, 1.0);
  const auto df = describing_function(m, ss, 1.0, {100.0}, 1);
  FrfRequest r = gmasim_experiments_test::two_point_frf(20.0, 100.0, 200.0);
  r.amplitude_A = 1.0;
  const FrfResult frf = run_frf(m, r);
  const FrfCurve& c = frf.curves.at(0);
  ASSERT_EQ(c.f_Hz.front(), 100.0);
  EXPECT_NEAR(df[0].gain_um_per_A / c.stepped_mag_um_per_A.front(), 1.0, 1e-9);
  EXPECT_NEAR(df[0].phase_deg, c.stepped_phase_deg.front(), 1e-6);
  EXPECT_GT(df[0].gain_um_per_A, 2.0 * df[0].small_signal_gain_um_per_A);  // large signal
  EXPECT_THAT(gmasim_test::input_error([&] { (void)describing_function(m, ss, 0.0, {10.0}); }),
              ::testing::HasSubstr("--amplitude"));
  EXPECT_THAT(gmasim_test::input_error([&] { (void)describing_function(m, ss, 1.0, {}); }),
              ::testing::HasSubstr("--frequencies"));
  // The bias too: beyond the coil's limit it is refused by name, not run into a divergence.
  EXPECT_THAT(gmasim_test::input_error([&] { (void)linearize_plant(m, 20.0, 1e9); }),
              ::testing::HasSubstr("bias current (--bias, bias_A) = 1e+09 A: must be in"));
}
