// The Jiles-Atherton lanes with a rod count other than the built-in actuator's 3 (docs/lanes.md):
// the kernel has an instance compiled for 3 rods and a generic one (any count, read at run time);
// models/single_rod.toml (one rod) takes the generic one. Each lane equals the width-1 instance
// bit for bit and equals the scalar step() (bit for bit since issue 38; before, to the rounding
// of their different exp: observed
// 1.7e-13 of the scales FollowTheScalarStep uses).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "lanes_test_util.hpp"

namespace lanes_rods_test {

using namespace gmasim;

const Model& model() {
  static const Model m = load_model(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod.toml");
  return m;
}

constexpr double kStep = 10e-6;

// n one-rod runs at 10..80 degC (gmasim_test::ReversingRuns).
struct OneRodRuns : gmasim_test::ReversingRuns {
  explicit OneRodRuns(std::size_t n) : ReversingRuns(model(), n, 10.0, 10.0, 8) {}
};

std::vector<double> state_numbers(const State& s) {
  std::vector<double> v = {s.t_s, s.current_A, s.y_m, s.y_stack_m, s.B_T};
  for (const auto& r : s.rods)
    for (double x : {r.H_A_per_m, r.Mirr_A_per_m, r.M_A_per_m, r.Hc_A_per_m, r.H_prev_A_per_m,
                     r.M_prev_A_per_m, r.x_m, r.v_m_per_s, r.F_N, r.mu_r, r.E_Pa, r.lambda, r.tau_s,
                     r.phi_Wb, r.k_rod_N_per_m, r.k_load_N_per_m, r.B_T})
      v.push_back(x);
  return v;
}

TEST(LanesRodCount, OneRodLanesEqualTheWidthOneInstance) {
  ASSERT_EQ(model().rods.size(), 1u);
  // 11 lanes: one full AVX-512 vector and a partial one (padding)
  gmasim_test::expect_lanes_equal_width_one(OneRodRuns(11), 1000, kStep, state_numbers);
}

TEST(LanesRodCount, OneRodLanesFollowTheScalarStep) {
  const std::size_t n = 11;
  const OneRodRuns runs(n);
  LaneBatch b = runs.batch();
  std::vector<State> scalar = runs.s;
  std::vector<double> cur(n), dt(n, kStep), t1(n);
  State s = runs.s[0];
  double worst = 0.0, y_pp = 0.0;
  for (long k = 1; k <= 2000; ++k) {
    const double t = static_cast<double>(k) * kStep;
    for (std::size_t i = 0; i < n; ++i) {
      cur[i] = runs.current(i, t);
      t1[i] = t;
      step(model(), runs.c[i], scalar[i], {cur[i], kStep});
      scalar[i].t_s = t;
    }
    b.step(cur, dt, t1);
    if (k % 100 != 0) continue;
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_FALSE(b.diverged(i)) << b.error(i);
      b.unpack(i, s);
      y_pp = std::max(y_pp, std::fabs(scalar[i].y_m));
      auto rel = [&](double x, double ref, double scale) {
        const double e = std::fabs(x - ref) / scale;
        worst = std::max(worst, e);
        EXPECT_EQ(e, 0.0) << "lane " << i << " step " << k;  // 0 since issue 38 (1.7e-13 before)
      };
      rel(s.y_m, scalar[i].y_m, 1e-6);  // [m]: relative to 1 um
      rel(s.B_T, scalar[i].B_T, 1.0);
      rel(s.rods[0].H_A_per_m, scalar[i].rods[0].H_A_per_m, 1e4);
      rel(s.rods[0].M_A_per_m, scalar[i].rods[0].M_A_per_m, 8e5);
    }
  }
  EXPECT_GT(y_pp, 1e-7);  // the rod moves (the largest |y| seen, > 0.1 um)
  std::printf(
      "one rod: lanes vs scalar step() largest relative difference %.3g, |y| up to %.3g m\n", worst,
      y_pp);
}

}  // namespace lanes_rods_test
