// Issue 41: compensate states what its schedule costs the coil. coil_copper_loss_W against the
// hand formula (a biased sine's I_rms^2 times the winding's R(T)), and the schedule table's
// copper_loss_W column (src/experiments/compensate.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "builtin_models.hpp"
#include "gmasim/experiments/compensate.hpp"
#include "gmasim/simulate/simulate.hpp"

using namespace gmasim;

TEST(CompensatePower, CopperLossIsTheSinesRmsSquaredTimesTheWindingsResistance) {
  const Model& m = gmasim_test::mdma();  // 1.5 ohm at 20 degC, alpha 3.93e-3 /K
  // 30 A p-p from -3 A: mean 12 A, amplitude 15 A: I_rms^2 = 144 + 112.5 = 256.5 A^2.
  EXPECT_NEAR(coil_copper_loss_W(m, -3.0, 30.0, 20.0), 256.5 * 1.5, 1e-9);
  EXPECT_NEAR(coil_copper_loss_W(m, -3.0, 30.0, 150.0), 256.5 * 1.5 * (1.0 + 3.93e-3 * 130.0),
              1e-9);
  EXPECT_NEAR(coil_copper_loss_W(m, 0.0, 0.0, 20.0), 0.0, 0.0);

  CompensateResult res;
  CompensatePoint p;
  p.temperature_C = 70.0;
  p.current_pp_A = 9.7;
  p.current_min_A = -3.0;
  res.points = {p};
  const Report r = compensate_report(m, CompensateRequest{}, res, nullptr);
  const Table& t = r.tables.at(0);
  const auto col = std::find(t.columns.begin(), t.columns.end(), "copper_loss_W");
  ASSERT_NE(col, t.columns.end());
  const auto j = static_cast<std::size_t>(col - t.columns.begin());
  EXPECT_EQ(t.rows.at(0).at(j).number, coil_copper_loss_W(m, -3.0, 9.7, 70.0));
}

// Issue 41: compensate's default target is one every temperature reaches. With the amplifier
// at 6 A the reference drive's stroke (8 A p-p from -3 A at 20 degC) is beyond the 150 degC
// reach, so the default target is lowered to that reach -- the stroke of the largest drive,
// which an independent run reproduces -- and every point is solved; the reference's stroke,
// given explicitly or with lower_target_to_reach off, leaves 150 degC unreachable.
TEST(CompensateReach, DefaultTargetIsTheSmallestReachWhenTheReferenceIsBeyondIt) {
  const Model& m = gmasim_test::mdma();
  CompensateRequest r;
  r.temperatures_C = {20.0, 150.0};
  r.max_current_A = 6.0;
  r.periods = 2.0;
  const CompensateResult res = run_compensate(m, r);
  ASSERT_EQ(res.points.size(), 2u);
  const CompensatePoint& hot = res.points[1];
  EXPECT_TRUE(res.target_lowered);
  EXPECT_LT(res.target_stroke_um, res.reference.stroke_um);
  EXPECT_EQ(res.target_stroke_um, std::min(res.points[0].reach_stroke_um, hot.reach_stroke_um));
  SimulationSettings s;
  s.temperature_C = 150.0;
  s.waveform = biased_sine(9.0, r.frequency_Hz, -3.0);  // the largest drive: -3 A to 6 A
  s.periods = r.periods;
  EXPECT_NEAR(simulate(m, s).metrics.stroke_um, hot.reach_stroke_um, 1e-9);
  for (const CompensatePoint& p : res.points) {
    EXPECT_TRUE(p.reachable && !p.diverged) << p.temperature_C << ": " << p.error;
    EXPECT_NEAR(p.stroke_um, res.target_stroke_um, r.tolerance_um);
    EXPECT_LE(p.current_max_A, r.max_current_A + 1e-12);
  }
  CompensateRequest keep = r;
  keep.lower_target_to_reach = false;
  CompensateRequest given = r;
  given.target_stroke_um = res.reference.stroke_um;
  for (const CompensateRequest& q : {keep, given}) {
    const CompensateResult k = run_compensate(m, q);
    EXPECT_FALSE(k.target_lowered);
    EXPECT_EQ(k.target_stroke_um, res.reference.stroke_um);
    EXPECT_TRUE(k.points[0].reachable);
    EXPECT_FALSE(k.points[1].reachable);
    EXPECT_EQ(k.points[1].reach_stroke_um, hot.reach_stroke_um);
  }
}
