// Issue 41: compensate states what its schedule costs the coil. coil_copper_loss_W against the
// hand formula (a biased sine's I_rms^2 times the winding's R(T)), and the schedule table's
// copper_loss_W column (src/experiments/compensate.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "builtin_models.hpp"
#include "gmasim/experiments/compensate.hpp"

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
