// The Preisach law in the batched SIMD lanes (src/lanes/preisach_lanes-inl.h, docs/lanes.md
// "Preisach lanes") on models/single_rod_preisach.toml: each lane equals the width-1 instance
// bit for bit (on the dispatched target and on the fallback); each lane equals the scalar step()
// bit for bit (the law is one text over the number type: gmasim/physics/preisach_law-inl.h),
// with lanes at different temperatures, current amplitudes and frequencies whose currents reverse
// inside the period (minor loops: pushes onto the extrema stack and wiping-out); make_states and
// simulate_lanes (the sweep's path) match make_state and simulate().
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "hwy/targets.h"
#include "lanes_test_util.hpp"

namespace preisach_lanes_test {

using namespace gmasim;

const Model& model() {
  static const Model m =
      load_model(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod_preisach.toml");
  return m;
}

constexpr double kStep = 10e-6;

// n Preisach runs at 0..80 degC (gmasim_test::ReversingRuns: minor loops).
struct PreisachRuns : gmasim_test::ReversingRuns {
  explicit PreisachRuns(std::size_t n) : ReversingRuns(model(), n, 0.0, 10.0, 9) {}
};

// The numbers step() sets, and each rod's extrema stack (depth, entries, the point now).
std::vector<double> state_numbers(const State& s) {
  std::vector<double> v = {s.t_s, s.current_A, s.y_m, s.y_stack_m, s.B_T};
  for (const auto& r : s.rods) {
    for (double x : {r.H_A_per_m, r.Mirr_A_per_m, r.M_A_per_m, r.Hc_A_per_m, r.x_m, r.v_m_per_s,
                     r.F_N, r.mu_r, r.E_Pa, r.lambda, r.tau_s, r.phi_Wb, r.B_T})
      v.push_back(x);
    const auto& h = r.preisach;
    v.push_back(h.n);
    for (int k = 0; k < h.n; ++k)
      for (double x : {h.x[k], h.mu[k], h.mc[k], h.mu_u[k]}) v.push_back(x);
    for (double x : {h.x_now, h.mu_now, h.mc_now, h.mu_u_now, h.last_dmc}) v.push_back(x);
  }
  return v;
}

TEST(PreisachLanes, EachLaneEqualsTheWidthOneInstance) {
  std::string why;
  ASSERT_TRUE(lanes_supported(model(), &why)) << why;
  gmasim_test::expect_lanes_equal_width_one(
      PreisachRuns(11), 600, kStep, state_numbers);  // a full AVX-512 vector and a partial one
}

// The fallback targets (SSE4, and EMU128 / SCALAR where compiled): each lane equals its width-1
// instance there too.
TEST(PreisachLanes, FallbackTargetsEqualTheirWidthOneInstance) {
  const PreisachRuns runs(5);
  int tried = 0;
  for (int64_t target : {int64_t{HWY_SSE4}, int64_t{HWY_EMU128}, int64_t{HWY_SCALAR}}) {
    hwy::SetSupportedTargetsForTest(target);
    const auto targets = hwy::SupportedAndGeneratedTargets();
    if (targets.empty() || targets.front() != target) continue;
    ++tried;
    gmasim_test::expect_lanes_equal_width_one(runs, 200, kStep, state_numbers);
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(tried, 1);
}

// Each lane against the scalar step() (PreisachLaw): 9 lanes, 3000 steps (1.5 to 6 periods), the
// scalar runs reversing and wiping out (else this tests nothing). The law is one text over the
// number type (gmasim/physics/preisach_law-inl.h: its Everett function, erfc and exp, Newton solve
// and trial), so every lane equals the scalar step bit for bit and the stacks keep the same
// depth: y, B, H, M, M_irr, mu_r and the point the stack is at (x_now, mu_now) compared exactly
// (before issue 38 the lanes had their own erfc and exp: 3.7e-11 to 1.7e-10 of y, depths
// differing where a periodic input stopped a rounding short of its own extremum).
TEST(PreisachLanes, FollowTheScalarStep) {
  const std::size_t n = 9;
  const PreisachRuns runs(n);
  LaneBatch b = runs.batch();
  std::vector<State> scalar = runs.s;
  std::vector<double> cur(n), dt(n, kStep), t1(n);
  std::vector<int> pushes(n, 0), wipes(n, 0);
  State s = runs.s[0];
  double worst = 0.0;
  int depth_differs = 0, checks = 0;
  for (long k = 1; k <= 3000; ++k) {
    const double t = static_cast<double>(k) * kStep;
    for (std::size_t i = 0; i < n; ++i) {
      cur[i] = runs.current(i, t);
      t1[i] = t;
      const int before = scalar[i].rods[0].preisach.n;
      step(model(), runs.c[i], scalar[i], {cur[i], kStep});
      scalar[i].t_s = t;
      const int after = scalar[i].rods[0].preisach.n;
      if (after > before) ++pushes[i];
      if (after < before) ++wipes[i];
    }
    b.step(cur, dt, t1);
    if (k % 100 != 0) continue;
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_FALSE(b.diverged(i)) << b.error(i);
      b.unpack(i, s);
      const State& r = scalar[i];
      auto rel = [&](double x, double ref, double scale, const char* what) {
        const double e = std::fabs(x - ref) / scale;
        worst = std::max(worst, e);
        EXPECT_EQ(x, ref) << what << " lane " << i << " step " << k;
      };
      rel(s.y_m, r.y_m, 1e-6, "y");
      rel(s.B_T, r.B_T, 1.0, "B");
      const RodState &got = s.rods[0], &ref = r.rods[0];
      rel(got.H_A_per_m, ref.H_A_per_m, 1e4, "H");
      rel(got.M_A_per_m, ref.M_A_per_m, 1e5, "M");
      rel(got.Mirr_A_per_m, ref.Mirr_A_per_m, 1e5, "M_irr");
      rel(got.mu_r, ref.mu_r, ref.mu_r, "mu_r");
      rel(got.preisach.mu_now, ref.preisach.mu_now, 1.0, "mu_now");
      rel(got.preisach.x_now, ref.preisach.x_now, std::max(1.0, std::fabs(ref.preisach.x_now)),
          "x_now");
      ++checks;
      if (got.preisach.n != ref.preisach.n) ++depth_differs;
      EXPECT_EQ(got.preisach.n, ref.preisach.n) << "lane " << i << " step " << k;
    }
  }
  std::printf(
      "Preisach lanes vs scalar step: largest relative difference %.3g; stack depths "
      "differ at %d of %d checks\n",
      worst, depth_differs, checks);
  for (std::size_t i = 0; i < n; ++i) {
    std::printf("lane %zu: reversals %d, wiping-outs %d\n", i, pushes[i], wipes[i]);
    EXPECT_GE(pushes[i], 4) << "lane " << i;  // reversals (minor loops) onto the stack
    EXPECT_GE(wipes[i], 2) << "lane " << i;
  }
}

// make_states (the ramp in lanes, rest_increment) against make_state: bit for bit (1.5e-14
// before the law was one text). The increment and the step allocate nothing.
TEST(PreisachLanes, MakeStatesMatchMakeState) {
  const std::size_t n = 6;
  const PreisachRuns runs(n);
  std::vector<const Model*> m(n, &model());
  std::vector<const Conditions*> c;
  std::vector<double> I0;
  for (std::size_t i = 0; i < n; ++i) {
    c.push_back(&runs.c[i]);
    I0.push_back(-2.0 + 0.8 * static_cast<double>(i));
  }
  const std::vector<State> got = make_states(m, c, I0);
  double worst = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const State ref = make_state(model(), runs.c[i], I0[i]);
    auto rel = [&](double x, double r, double scale) {
      const double e = std::fabs(x - r) / scale;
      worst = std::max(worst, e);
      EXPECT_EQ(x, r) << "lane " << i;
    };
    rel(got[i].y_m, ref.y_m, 1e-6);
    rel(got[i].B_T, ref.B_T, 1.0);
    rel(got[i].rods[0].H_A_per_m, ref.rods[0].H_A_per_m, 1e4);
    rel(got[i].rods[0].M_A_per_m, ref.rods[0].M_A_per_m, 1e5);
    EXPECT_EQ(got[i].rods[0].preisach.n, ref.rods[0].preisach.n) << "lane " << i;
  }
  std::printf("Preisach make_states vs make_state: largest relative difference %.3g\n", worst);
  LaneBatch a = runs.batch();
  std::vector<double> cur(n), pm(n), dt(n, kStep), t1(n);
  gmasim_test::g_allocations = 0;
  gmasim_test::g_counting = true;
  for (int k = 1; k <= 20; ++k) {
    for (std::size_t i = 0; i < n; ++i) {
      cur[i] = 0.1 * k * static_cast<double>(i);
      pm[i] = runs.c[i].pm_scale;
      t1[i] = k * kStep;
    }
    a.rest_increment(cur, pm);
    a.step(cur, dt, t1);
  }
  gmasim_test::g_counting = false;
  EXPECT_EQ(gmasim_test::g_allocations.load(), 0);
}

// simulate_lanes (what `gmasim sweep` runs) against simulate(): the metrics of biased and
// bipolar sines at three temperatures: bit for bit (1.2e-13 of the stroke before the law was
// one text).
TEST(PreisachLanes, SimulateLanesMatchesSimulate) {
  const std::vector<SimulationSettings> set =
      gmasim_test::biased_sine_settings({20.0, 50.0, 80.0}, {2.0, 6.0}, 100.0, 2);
  const double worst = gmasim_test::expect_simulate_lanes_matches(model(), set, 0.0);
  std::printf("Preisach simulate_lanes vs simulate: largest relative difference %.3g\n", worst);
}

}  // namespace preisach_lanes_test
