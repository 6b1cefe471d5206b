// Batched SIMD lanes (gmasim/lanes.hpp, docs/lanes.md): each lane equals the width-1
// instance of the same kernel bit for bit, on the dispatched target and on the fallback
// targets; the lanes follow the scalar step() to the tolerance of their different exp/cos;
// a lane's divergence is its own; the step allocates nothing; simulate_lanes reproduces
// simulate()'s metrics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "alloc_counter.hpp"
#include "gmasim/io.hpp"
#include "gmasim/lanes.hpp"
#include "gmasim/model.hpp"
#include "gmasim/simulate.hpp"
#include "hwy/targets.h"

namespace {

using namespace gmasim;

const Model& builtin() {
  static const Model m = load_model("");
  return m;
}

// n simulations at rest: temperatures 20..75 degC, 10 Hz biased sines of 4..10 A.
struct Runs {
  std::vector<Conditions> c;
  std::vector<State> s;
  std::vector<double> pp;
  explicit Runs(std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      c.push_back(make_conditions(builtin(), 20.0 + 5.0 * static_cast<double>(i)));
      pp.push_back(4.0 + 0.5 * static_cast<double>(i % 13));
      s.push_back(make_state(builtin(), c.back(), 0.0));
    }
  }
  double current(std::size_t i, double t) const {
    return 0.5 * pp[i] * (1.0 - std::cos(2.0 * 3.141592653589793 * 10.0 * t));
  }
  LaneBatch batch() const {
    std::vector<const Model*> m(c.size(), &builtin());
    std::vector<const Conditions*> cp;
    std::vector<const State*> sp;
    for (std::size_t i = 0; i < c.size(); ++i) {
      cp.push_back(&c[i]);
      sp.push_back(&s[i]);
    }
    return LaneBatch(m, cp, sp);
  }
};

constexpr double kDt = 10e-6;

// The numbers of a State that step() sets, in one list.
std::vector<double> numbers(const State& s) {
  std::vector<double> v = {s.t_s, s.current_A, s.y_m,         s.y_stack_m,
                           s.q_m, s.z_m,       s.z_v_m_per_s, s.B_T};
  for (const auto& r : s.rods)
    for (double x : {r.H_A_per_m, r.Mirr_A_per_m, r.M_A_per_m, r.Hc_A_per_m, r.H_prev_A_per_m,
                     r.M_prev_A_per_m, r.x_m, r.v_m_per_s, r.F_N, r.mu_r, r.E_Pa, r.lambda, r.tau_s,
                     r.phi_Wb, r.k_rod_N_per_m, r.k_load_N_per_m, r.K_osc_N_per_m, r.B_T})
      v.push_back(x);
  return v;
}

// Steps every lane of a and b (b: the width-1 instance) and checks bitwise equality.
void expect_lanes_equal_width_one(const Runs& runs, long steps) {
  LaneBatch a = runs.batch(), b = runs.batch();
  const std::size_t n = runs.c.size();
  std::vector<double> cur(n), dt(n, kDt), t1(n);
  State sa = runs.s[0], sb = runs.s[0];
  for (long k = 1; k <= steps; ++k) {
    const double t = static_cast<double>(k) * kDt;
    for (std::size_t i = 0; i < n; ++i) {
      cur[i] = runs.current(i, t);
      t1[i] = t;
    }
    a.step(cur, dt, t1);
    b.step(cur, dt, t1, true);
    if (k % 50 != 0 && k != steps) continue;
    for (std::size_t i = 0; i < n; ++i) {
      a.unpack(i, sa);
      b.unpack(i, sb);
      const auto va = numbers(sa), vb = numbers(sb);
      ASSERT_EQ(0, std::memcmp(va.data(), vb.data(), va.size() * sizeof(double)))
          << "lane " << i << " step " << k << " target " << lanes_target();
      ASSERT_FALSE(a.diverged(i)) << a.error(i);
    }
  }
}

TEST(Lanes, EachLaneEqualsTheWidthOneInstance) {
  // 11 lanes: one full AVX-512 vector and a partial one (padding).
  expect_lanes_equal_width_one(Runs(11), 1500);
  std::printf("lanes: target %s, %d doubles per vector\n", lanes_target().c_str(), lanes_width());
}

// The fallback targets (SSE4: 2 lanes, and the portable EMU128 the baseline build compiles)
// give each lane the width-1 numbers too, and the same run as the best target to the
// rounding of FMA-based vs separate multiply-add in Highway's exp/cos (observed ~1e-13).
TEST(Lanes, FallbackTargetsAgree) {
  const Runs runs(5);
  auto run = [&](LaneBatch& b, std::vector<double>& last) {
    std::vector<double> cur(5), dt(5, kDt), t1(5);
    for (long k = 1; k <= 1000; ++k) {
      for (std::size_t i = 0; i < 5; ++i) {
        cur[i] = runs.current(i, static_cast<double>(k) * kDt);
        t1[i] = static_cast<double>(k) * kDt;
      }
      b.step(cur, dt, t1);
    }
    State s = runs.s[0];
    last.clear();
    for (std::size_t i = 0; i < 5; ++i) {
      b.unpack(i, s);
      for (double x : numbers(s)) last.push_back(x);
    }
  };
  LaneBatch best = runs.batch();
  std::vector<double> ref, got;
  run(best, ref);
  const int best_width = lanes_width();
  int tried = 0;
  for (int64_t target : {int64_t{HWY_SSE4}, int64_t{HWY_EMU128}, int64_t{HWY_SCALAR}}) {
    if ((hwy::SupportedAndGeneratedTargets().size() == 0)) break;
    hwy::SetSupportedTargetsForTest(target);
    const auto targets = hwy::SupportedAndGeneratedTargets();
    if (targets.empty() || targets.front() != target) continue;  // not compiled in
    ++tried;
    EXPECT_LE(lanes_width(), best_width);
    expect_lanes_equal_width_one(runs, 400);
    LaneBatch b = runs.batch();
    run(b, got);
    for (std::size_t q = 0; q < ref.size(); ++q)
      EXPECT_NEAR(got[q], ref[q], 1e-9 * std::fabs(ref[q]) + 1e-300)
          << "value " << q << " on " << hwy::TargetName(target);
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(tried, 1);
  EXPECT_EQ(lanes_width(), best_width);
}

}  // namespace
