// loop_widths (gmasim/identify/identify.hpp): the width of a hysteresis loop at fractions of its
// response span, which identify's report gives measured beside simulated (issue 39 item 4).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gmasim/identify/identify.hpp"

namespace {

// A parallelogram loop: the drive rises 0 -> 10 with the response max(0, x - 1), then falls
// 10 -> 0 with x + 1 (the jumps at the ends are vertical, which no level crosses between two
// samples of one drive), so at every level the falling branch lies 2 drive units left of the
// rising one; linear interpolation is exact on these lines. mirror: the same loop on -x after
// it (a butterfly's second half).
void parallelogram(std::vector<double>& x, std::vector<double>& y, bool mirror) {
  for (int pass = 0; pass < (mirror ? 2 : 1); ++pass) {
    const double s = pass == 0 ? 1.0 : -1.0;
    for (int i = 0; i <= 100; ++i) {
      x.push_back(s * 0.1 * i);
      y.push_back(std::max(0.0, 0.1 * i - 1.0));
    }
    for (int i = 100; i >= 0; --i) {
      x.push_back(s * 0.1 * i);
      y.push_back(0.1 * i + 1.0);
    }
  }
}

TEST(LoopWidth, AParallelogramHasItsWidthAtEveryLevel) {
  std::vector<double> x, y;
  parallelogram(x, y, false);
  const auto w = gmasim::loop_widths(x, y, 0.0, 11.0);
  for (double v : w) EXPECT_NEAR(v, 2.0, 1e-12);
  // the mirrored half of a butterfly is not averaged in (observed exactly 2 as well)
  std::vector<double> xb, yb;
  parallelogram(xb, yb, true);
  for (double v : gmasim::loop_widths(xb, yb, 0.0, 11.0)) EXPECT_NEAR(v, 2.0, 1e-12);
  // a level the rising branch never reaches (above 9): NaN, not a number made up
  const auto high = gmasim::loop_widths(x, y, 0.0, 12.0);  // 80 %: 9.6
  EXPECT_NEAR(high[0], 2.0, 1e-12);
  EXPECT_TRUE(std::isnan(high[3]));
  // a loop that closes (the same branch both ways): width 0
  std::vector<double> xc = x, yc = x;
  for (auto& v : yc) v = 2.0 * v;
  for (double v : gmasim::loop_widths(xc, yc, 0.0, 20.0)) EXPECT_NEAR(v, 0.0, 1e-12);
}

}  // namespace
