// Batched SIMD lanes (gmasim/lanes.hpp, docs/lanes.md): each lane equals the width-1
// instance of the same kernel bit for bit, on the dispatched target and on the fallback
// targets; the Jiles-Atherton lanes equal the scalar step() bit for bit since the laws are written
// once (issue 38: gmasim/physics/laws-inl.h, ja_law-inl.h); a lane's divergence is its own; the
// step allocates nothing; simulate_lanes reproduces simulate()'s metrics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "alloc_counter.hpp"
#include "builtin_models.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "hwy/targets.h"
#include "lanes_test_util.hpp"

namespace {

using gmasim_test::expect_lanes_equal_width_one;
using gmasim_test::mdma;

using namespace gmasim;

// n simulations at rest: temperatures 20..75 degC, 10 Hz biased sines of 4..10 A.
struct Runs {
  std::vector<Conditions> c;
  std::vector<State> s;
  std::vector<double> pp;
  explicit Runs(std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      c.push_back(make_conditions(mdma(), 20.0 + 5.0 * static_cast<double>(i)));
      pp.push_back(4.0 + 0.5 * static_cast<double>(i % 13));
      s.push_back(make_state(mdma(), c.back(), 0.0));
    }
  }
  double current(std::size_t i, double t) const {
    return 0.5 * pp[i] * (1.0 - std::cos(2.0 * 3.141592653589793 * 10.0 * t));
  }
  LaneBatch batch() const { return gmasim_test::lane_batch(mdma(), c, s); }
};

constexpr double kDt = 10e-6;

// The numbers of a State that step() sets, in one list.
std::vector<double> numbers(const State& s) {
  std::vector<double> v = {s.t_s, s.current_A, s.y_m,         s.y_stack_m,
                           s.q_m, s.z_m,       s.z_v_m_per_s, s.B_T};
  for (const auto& r : s.rods)
    for (double x : {r.H_A_per_m,
                     r.Mirr_A_per_m,
                     r.M_A_per_m,
                     r.Hc_A_per_m,
                     r.H_prev_A_per_m,
                     r.M_prev_A_per_m,
                     r.H_prev2_A_per_m,
                     r.M_prev2_A_per_m,
                     r.x_m,
                     r.v_m_per_s,
                     r.F_N,
                     r.mu_r,
                     r.E_Pa,
                     r.lambda,
                     r.tau_s,
                     r.phi_Wb,
                     r.k_rod_N_per_m,
                     r.k_load_N_per_m,
                     r.K_osc_N_per_m,
                     r.B_T})
      v.push_back(x);
  return v;
}

TEST(Lanes, EachLaneEqualsTheWidthOneInstance) {
  // 11 lanes: one full AVX-512 vector and a partial one (padding).
  expect_lanes_equal_width_one(Runs(11), 1500, kDt, numbers);
  std::printf("lanes: target %s, %d doubles per vector\n", lanes_target().c_str(), lanes_width());
}

// The fallback targets (SSE4: 2 lanes, and the portable EMU128 the baseline build compiles)
// give each lane the width-1 numbers too, and the same run as the best target bit for bit (libm
// lane by lane, no contraction: bit for bit since the laws are written once (issue 38:
// gmasim/physics/laws-inl.h, ja_law-inl.h)); before, to the rounding of FMA-based vs separate
// multiply-add in Highway's exp/cos (observed 3.7e-12 SSE4 vs AVX-512, 1.3e-11 before the lanes
// mirrored the scalar's one-division Langevin; tolerance 1e-10). The CI's sanitizer build compiles
// AVX2, SSE4 and the scalar baseline only (CMakeLists.txt, HWY_DISABLED_TARGETS): there the
// fallback tried is SSE4 against AVX2.
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
    std::printf("fallback %s: %d doubles per vector\n", hwy::TargetName(target), lanes_width());
    EXPECT_LE(lanes_width(), best_width);
    expect_lanes_equal_width_one(runs, 400, kDt, numbers);
    LaneBatch b = runs.batch();
    run(b, got);
    double worst = 0.0;
    for (std::size_t q = 0; q < ref.size(); ++q) {
      const double e = std::fabs(got[q] - ref[q]) / std::max(std::fabs(ref[q]), 1e-300);
      worst = std::max(worst, e);
      EXPECT_EQ(e, 0.0) << "value " << q << " on " << hwy::TargetName(target);
    }
    std::printf("fallback %s vs best: largest relative difference %.3g\n", hwy::TargetName(target),
                worst);
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(tried, 1);
  EXPECT_EQ(lanes_width(), best_width);
}

// The lanes against the scalar step(): the same Newton path (stepfast2's joint Newton in
// (H, M): quadratic first guess, one law evaluation per solve, the last iterate committed,
// L D L^T rod solve), so they differ in Highway's exp against libm's in the magnetic laws' lanes
// (a few ulp; the mechanics laws are the scalar's own: tests/test_laws_lanes.cpp) and where that
// rounding moves a Newton convergence decision. Now equal bit for bit since the laws are written
// once (issue 38: gmasim/physics/laws-inl.h, ja_law-inl.h), the kernel's stages operation for
// operation the scalar step's: every difference 0. Before, observed after 3000 steps, relative to
// the scales below: y 6.0e-13 (of 1 um), B 2.8e-15, H 1.3e-13 (of 1e4 A/m), M 6.2e-15 (5.8e-13,
// 2.4e-15, 1.4e-13, 8.3e-15 while the mechanics had its own lane
// copy; 3.9e-13, 2.6e-15, 1.4e-13, 5.8e-15 before the lanes mirrored the skipped confirming solve,
// the oscillator's series and M_an carried; 4.2e-9 when the lanes mirrored the step of c77ea92);
// tolerance 7e-12 (now 0: any difference fails).
TEST(Lanes, FollowTheScalarStep) {
  const Runs runs(9);
  LaneBatch b = runs.batch();
  std::vector<State> scalar = runs.s;
  const std::size_t n = 9;
  std::vector<double> cur(n), dt(n, kDt), t1(n);
  State s = runs.s[0];
  double worst = 0.0, worst_of[4] = {};
  for (long k = 1; k <= 3000; ++k) {
    const double t = static_cast<double>(k) * kDt;
    for (std::size_t i = 0; i < n; ++i) {
      cur[i] = runs.current(i, t);
      t1[i] = t;
      step(mdma(), runs.c[i], scalar[i], {cur[i], kDt});
      scalar[i].t_s = t;
    }
    b.step(cur, dt, t1);
    if (k % 100 != 0) continue;
    for (std::size_t i = 0; i < n; ++i) {
      b.unpack(i, s);
      auto rel = [&](double x, double ref, double scale, int q = 0) {
        const double e = std::fabs(x - ref) / scale;
        worst = std::max(worst, e);
        worst_of[q] = std::max(worst_of[q], e);
        EXPECT_EQ(e, 0.0) << "lane " << i << " step " << k;
      };
      rel(s.y_m, scalar[i].y_m, 1e-6);  // [m]: relative to 1 um
      rel(s.B_T, scalar[i].B_T, 1.0, 1);
      for (std::size_t r = 0; r < s.rods.size(); ++r) {
        rel(s.rods[r].H_A_per_m, scalar[i].rods[r].H_A_per_m, 1e4, 2);
        rel(s.rods[r].M_A_per_m, scalar[i].rods[r].M_A_per_m, 8e5, 3);
      }
    }
  }
  std::printf(
      "lanes vs scalar step(): largest relative difference %.3g (y %.3g, B %.3g, H %.3g, M %.3g)\n",
      worst, worst_of[0], worst_of[1], worst_of[2], worst_of[3]);
  // The lanes skip the confirming circuit solve where step() does (its test, per lane): the
  // lanes' solves are step()'s, one a step (observed: equal, 27000 of 27000 lane-steps); a
  // vector solves while any of its lanes needs it.
  long scalar_solves = 0;
  for (std::size_t i = 0; i < n; ++i)
    scalar_solves += scalar[i].newton_solves - runs.s[i].newton_solves;
  EXPECT_EQ(static_cast<long>(b.newton_solves()), scalar_solves);
  EXPECT_LE(b.newton_solves(), static_cast<std::size_t>(1.1 * 3000 * n));
  EXPECT_GE(b.vector_solves() * static_cast<std::size_t>(lanes_width()), b.newton_solves());
  std::printf("circuit solves: lanes %zu, step() %ld over %zu lane-steps; %zu vector solves\n",
              b.newton_solves(), scalar_solves, 3000 * n, b.vector_solves());
}

// The Jiles-Atherton law's safeguard (its joint_trial solves eq. (9) fully where the joint
// Newton iterate's residual exceeds 1e-3 M_s^T) in the lanes: a current that jumps from rest to
// 6..11 A in one step in the even lanes only (the odd lanes run their sines), so the full solve
// runs masked, in some lanes of a vector and not in others (observed: 192 full solves over
// steps 1-100 at the safeguard's 1e-3 M_s^T; 983 at its earlier 1e-5 M_s^T). Each lane equals the
// width-1 instance bit for bit and follows the scalar step() as FollowTheScalarStep's lanes do:
// observed 1.6e-13 relative over steps 1-100 (a full solve the lanes skipped leaves ~1e-10: the
// ramp's 4.2e-10 before they mirrored it); now 0, as there. (Later, the even lanes sit at ~2e5
// A/m, deep in saturation, where lanes and scalar part at the Newton solve's field tolerance, 1e-11
// |H|: 2e-6 A/m, 2e-10 of the 1e4 A/m scale used here; no full solve runs there.)
TEST(Lanes, SafeguardSolvesEq9WhereTheScalarLawDoes) {
  const std::size_t n = 11;
  const Runs runs(n);
  auto current = [&](std::size_t i, double t) {
    return i % 2 == 0 ? 6.0 + 0.5 * static_cast<double>(i) : runs.current(i, t);
  };
  LaneBatch a = runs.batch(), b = runs.batch();
  std::vector<State> scalar = runs.s;
  std::vector<double> cur(n), dt(n, kDt), t1(n);
  State sa = runs.s[0], sb = runs.s[0];
  double worst = 0.0;
  for (long k = 1; k <= 100; ++k) {
    const double t = static_cast<double>(k) * kDt;
    for (std::size_t i = 0; i < n; ++i) {
      cur[i] = current(i, t);
      t1[i] = t;
      step(mdma(), runs.c[i], scalar[i], {cur[i], kDt});
      scalar[i].t_s = t;
    }
    a.step(cur, dt, t1);
    b.step(cur, dt, t1, true);
    if (k == 1) {
      EXPECT_GE(a.full_solves(), n / 2) << "the jump did not take the full solve";
      EXPECT_EQ(a.full_solves(), b.full_solves());
    }
    if (k % 5 != 0 && k > 3) continue;
    for (std::size_t i = 0; i < n; ++i) {
      a.unpack(i, sa);
      b.unpack(i, sb);
      const auto va = numbers(sa), vb = numbers(sb);
      ASSERT_EQ(0, std::memcmp(va.data(), vb.data(), va.size() * sizeof(double))) << "lane " << i;
      ASSERT_FALSE(a.diverged(i)) << a.error(i);
      auto rel = [&](double x, double ref, double scale) {
        const double e = std::fabs(x - ref) / scale;
        worst = std::max(worst, e);
        EXPECT_EQ(e, 0.0) << "lane " << i << " step " << k;
      };
      rel(sa.y_m, scalar[i].y_m, 1e-6);
      rel(sa.B_T, scalar[i].B_T, 1.0);
      for (std::size_t r = 0; r < sa.rods.size(); ++r) {
        rel(sa.rods[r].H_A_per_m, scalar[i].rods[r].H_A_per_m, 1e4);
        rel(sa.rods[r].M_A_per_m, scalar[i].rods[r].M_A_per_m, 8e5);
      }
    }
  }
  std::printf("safeguard: %zu full solves of eq. 9 in the lanes; lanes vs step() %.3g\n",
              a.full_solves(), worst);
}

// A lane that diverges stops there with its own diagnosis (time, rod, quantity); the others
// go on exactly as without it.
TEST(Lanes, DivergenceIsPerLane) {
  Runs runs(4), alone(4);
  runs.pp[2] = 1e12;  // an absurd current in lane 2 only
  LaneBatch b = runs.batch(), ref = alone.batch();
  std::vector<double> cur(4), cur_ref(4), dt(4, kDt), t1(4);
  for (long k = 1; k <= 200; ++k) {
    const double t = static_cast<double>(k) * kDt;
    for (std::size_t i = 0; i < 4; ++i) {
      cur[i] = runs.current(i, t);
      cur_ref[i] = alone.current(i, t);
      t1[i] = t;
    }
    b.step(cur, dt, t1);
    ref.step(cur_ref, dt, t1);
  }
  EXPECT_TRUE(b.diverged(2));
  const std::string e = b.error(2);
  EXPECT_NE(e.find("t = "), std::string::npos) << e;
  EXPECT_NE(e.find("rod"), std::string::npos) << e;
  State sa = runs.s[0], sb = runs.s[0];
  for (std::size_t i : {0, 1, 3}) {
    EXPECT_FALSE(b.diverged(i));
    b.unpack(i, sa);
    ref.unpack(i, sb);
    EXPECT_EQ(numbers(sa), numbers(sb)) << "lane " << i;
  }
  // A scalar run with that current throws; the lane's text names the same quantity.
  State s = runs.s[2];
  std::string scalar_error;
  try {
    for (long k = 1; k <= 200; ++k) {
      const double t = static_cast<double>(k) * kDt;
      step(mdma(), runs.c[2], s, {runs.current(2, t), kDt});
      s.t_s = t;
    }
  } catch (const DivergenceError& err) {
    scalar_error = err.quantity;
  }
  ASSERT_FALSE(scalar_error.empty());
  EXPECT_NE(e.find(scalar_error), std::string::npos) << e << " vs " << scalar_error;
}

// The batched step allocates nothing (buffers sized once, in the constructor).
TEST(Lanes, StepAllocatesNothing) {
  const Runs runs(10);
  LaneBatch b = runs.batch();
  std::vector<double> cur(10, 3.0), dt(10, kDt), t1(10, kDt);
  b.step(cur, dt, t1);
  gmasim_test::g_allocations = 0;
  gmasim_test::g_counting = true;
  for (int k = 2; k < 50; ++k) {
    for (double& t : t1) t = k * kDt;
    b.step(cur, dt, t1);
    b.step(cur, dt, t1, true);
  }
  gmasim_test::g_counting = false;
  EXPECT_EQ(gmasim_test::g_allocations.load(), 0);
}

// LaneBatch::record writes the row simulate()'s record() writes from the unpacked state.
TEST(Lanes, RecordIsTheUnpackedStatesRow) {
  const Runs runs(3);
  LaneBatch b = runs.batch();
  std::vector<double> cur(3), dt(3, kDt), t1(3);
  for (long k = 1; k <= 300; ++k) {
    for (std::size_t i = 0; i < 3; ++i) {
      cur[i] = runs.current(i, static_cast<double>(k) * kDt);
      t1[i] = static_cast<double>(k) * kDt;
    }
    b.step(cur, dt, t1);
  }
  State s = runs.s[0];
  for (std::size_t i = 0; i < 3; ++i) {
    TimeSeries ts;
    ts.columns.assign(6 + 9 * s.rods.size(), {});
    b.record(i, runs.c[i].thermal_expansion_m, ts);
    b.unpack(i, s);
    std::vector<double> want = {s.t_s,
                                s.current_A,
                                s.y_m * 1e6,
                                s.B_T,
                                runs.c[i].thermal_expansion_m * 1e6,
                                s.y_stack_m * 1e6};
    for (const auto& r : s.rods)
      for (double x : {r.H_A_per_m, r.M_A_per_m, r.mu_r, r.E_Pa * 1e-9, r.lambda * 1e6, r.F_N,
                       r.x_m * 1e6, r.tau_s * 1e3, r.B_T})
        want.push_back(x);
    ASSERT_EQ(want.size(), ts.columns.size());
    for (std::size_t q = 0; q < want.size(); ++q) {
      ASSERT_EQ(ts.columns[q].size(), 1u);
      EXPECT_EQ(ts.columns[q][0], want[q]) << "lane " << i << " column " << q;
    }
    EXPECT_GT(std::fabs(s.y_m), 0.0);
  }
}

// make_states: make_state's ramp in lanes. Each lane's rest state equals the width-1
// instance's bit for bit, and make_state's to the lanes' rounding: observed 8.1e-14 relative
// over y, B and every rod's H, M and x, with the lanes mirroring the scalar law's safeguard
// (eq. 9 solved fully where the joint step's residual exceeds 1e-3 M_s; 4.2e-10 without it);
// tolerance 6e-13; now equal (bit for bit since the laws are written once (issue 38:
// gmasim/physics/laws-inl.h, ja_law-inl.h)). The ramp's increment allocates nothing.
TEST(Lanes, MakeStatesMatchMakeState) {
  const Runs runs(9);
  std::vector<const Model*> m(9, &mdma());
  std::vector<const Conditions*> c;
  std::vector<double> I0;
  for (std::size_t i = 0; i < 9; ++i) {
    c.push_back(&runs.c[i]);
    I0.push_back(0.5 * static_cast<double>(i));
  }
  const std::vector<State> got = make_states(m, c, I0);
  double worst = 0.0;
  for (std::size_t i = 0; i < 9; ++i) {
    const State ref = make_state(mdma(), runs.c[i], I0[i]);
    auto rel = [&](double x, double r, double scale) {
      const double e = std::fabs(x - r) / scale;
      worst = std::max(worst, e);
      EXPECT_EQ(e, 0.0) << "lane " << i;
    };
    rel(got[i].y_m, ref.y_m, 1e-6);
    rel(got[i].B_T, ref.B_T, 1.0);
    for (std::size_t r = 0; r < ref.rods.size(); ++r) {
      rel(got[i].rods[r].H_A_per_m, ref.rods[r].H_A_per_m, 1e4);
      rel(got[i].rods[r].M_A_per_m, ref.rods[r].M_A_per_m, 8e5);
      rel(got[i].rods[r].x_m, ref.rods[r].x_m, 1e-6);
    }
  }
  std::printf("make_states vs make_state: largest relative difference %.3g\n", worst);
  EXPECT_GT(std::fabs(got[8].B_T - got[0].B_T), 0.0);  // the currents differ
  // The increment: each lane equals the width-1 instance, without allocating.
  LaneBatch a = runs.batch(), b = runs.batch();
  std::vector<double> cur(9), pm(9);
  gmasim_test::g_allocations = 0;
  gmasim_test::g_counting = true;
  for (int k = 1; k <= 40; ++k) {
    for (std::size_t i = 0; i < 9; ++i) {
      cur[i] = 0.1 * k * static_cast<double>(i);
      pm[i] = runs.c[i].pm_scale;
    }
    a.rest_increment(cur, pm);
    b.rest_increment(cur, pm, true);
  }
  gmasim_test::g_counting = false;
  EXPECT_EQ(gmasim_test::g_allocations.load(), 0);
  State sa = runs.s[0], sb = runs.s[0];
  for (std::size_t i = 0; i < 9; ++i) {
    a.unpack(i, sa);
    b.unpack(i, sb);
    const auto va = numbers(sa), vb = numbers(sb);
    ASSERT_EQ(0, std::memcmp(va.data(), vb.data(), va.size() * sizeof(double))) << "lane " << i;
  }
}

// simulate_lanes: each setting's metrics as simulate() gives them, bit for bit since the laws are
// written once (issue 38: gmasim/physics/laws-inl.h, ja_law-inl.h) (1e-9 relative before).
TEST(Lanes, SimulateLanesMatchesSimulate) {
  const std::vector<SimulationSettings> set =
      gmasim_test::biased_sine_settings({20.0, 60.0, 110.0}, {4.0, 8.0}, 50.0, 1);
  const double worst = gmasim_test::expect_simulate_lanes_matches(mdma(), set, 0.0);
  std::printf("simulate_lanes vs simulate: largest relative difference %.3g\n", worst);
}

// The identify objective with its records in lanes (identify/record_lanes.cpp) against one
// scalar run per record: every residual (12 records of y and B, 2 periods, 100 samples per
// period, with one pre-cycle-free sine each), bit for bit since the laws are written once (issue
// 38: gmasim/physics/laws-inl.h, ja_law-inl.h). Residuals are in % of each record's p-p; observed
// difference ~1e-10 % before, tolerance 1e-8 %; now equal.
TEST(Lanes, ObjectiveResidualsMatchTheScalarRuns) {
  SyntheticRequest req;
  req.samples_per_period = 100;
  req.noise_pct = 0.0;
  req.flux_noise_pct = 0.0;
  req.objective.steps_per_period = 100;
  const MeasurementSet data = synthesize_measurements(mdma(), req);
  const FitSpec fit = load_fit_spec("rod1.ja.k0_A_per_m:1500:6000:log,material.chi_m:8:50:log");
  ObjectiveSettings s;
  s.steps_per_period = 100;
  s.flux_weight = 1.0;
  const Objective batched(builtin_model_spec(), data, fit, s);
  s.lanes = false;
  const Objective scalar(builtin_model_spec(), data, fit, s);
  std::vector<double> u = batched.start_unit();
  u[0] = 0.37;
  std::vector<double> ra(batched.residual_count()), rb(scalar.residual_count());
  ASSERT_TRUE(batched.residuals(u.data(), ra.data()));
  ASSERT_TRUE(scalar.residuals(u.data(), rb.data()));
  double worst = 0.0;
  for (std::size_t i = 0; i < ra.size(); ++i) {
    worst = std::max(worst, std::fabs(ra[i] - rb[i]));
    EXPECT_EQ(ra[i], rb[i]) << "residual " << i;
  }
  std::printf("objective lanes vs scalar: %zu residuals, largest difference %.3g %%\n", ra.size(),
              worst);
  EXPECT_GT(std::fabs(ra[0]) + std::fabs(ra[ra.size() / 2]), 0.0);  // not the truth
}

// The calibration's objective (calibration/consistent.toml: ten claim targets and the modulus,
// seven biased-sine runs) with its runs in lanes against the scalar path (lanes = false): the
// sine runs (identify/sine_lanes.cpp) and every quasi-static ramp of its targets in one batch
// (the sine runs' start states, the modulus target's state at rest, the first resonance's bias
// ramp: make_states; then the bias point's DC settling in the eighth lane beside the seven
// sines) against one run_sine / make_state / settle_at_bias each, at the start and at a point
// away from it: equal, bit for bit since the laws are written once (issue 38:
// gmasim/physics/laws-inl.h, ja_law-inl.h). Before, observed: residuals (% of each target's
// scale) 2.05e-10 % apart, tolerance 2e-9 % (9.5e-12 % before issue 37, whose scales are the
// claims' tolerances, up to 4.4 times smaller, and whose runs take the claims' step, 25 us for 200
// us, over 3 periods for 2: the same relative agreement of the targets in residuals up to 35 times
// larger); the targets that read nothing but a ramp (modulus: E_G at rest; first resonance: the
// settled, linearised bias point) 1.6e-15 to 1.1e-14 relative, tolerance 1.2e-13; any
// target 1.9e-12 to 2.5e-12, tolerance 2e-11.
TEST(Lanes, TargetRunsAndRampsMatchTheScalarPath) {
  const std::string src = GMASIM_SOURCE_DIR;
  const ModelSpec start = load_model_spec(src + "/calibration/start/consistent.toml");
  const FitSpec fit = load_fit_spec(src + "/calibration/consistent.toml");
  ObjectiveSettings s;
  const Objective batched(start, MeasurementSet{}, fit, s);
  s.lanes = false;
  const Objective scalar(start, MeasurementSet{}, fit, s);
  std::vector<double> u = batched.start_unit();
  double worst = 0.0, worst_ramp = 0.0, worst_target = 0.0;
  int ramp_targets = 0;
  for (int point = 0; point < 2; ++point) {
    if (point == 1)
      for (std::size_t j = 0; j < u.size(); ++j) u[j] = 0.2 + 0.6 * static_cast<double>(j % 4) / 3;
    std::vector<double> ra(batched.residual_count()), rb(scalar.residual_count());
    ASSERT_TRUE(batched.residuals(u.data(), ra.data()));
    ASSERT_TRUE(scalar.residuals(u.data(), rb.data()));
    for (std::size_t i = 0; i < ra.size(); ++i) {
      worst = std::max(worst, std::fabs(ra[i] - rb[i]));
      EXPECT_EQ(ra[i], rb[i]) << "point " << point << ", residual " << i;
      EXPECT_GT(std::fabs(ra[i]), 1e-3) << "residual " << i << " is not a target's error";
    }
    const auto ta = batched.target_fits(u), tb = scalar.target_fits(u);
    ASSERT_EQ(ta.size(), tb.size());
    for (std::size_t i = 0; i < ta.size(); ++i) {
      ASSERT_FALSE(ta[i].failed || tb[i].failed) << ta[i].label;
      const double rel = std::fabs(ta[i].simulated / tb[i].simulated - 1.0);
      const bool ramp_only = ta[i].kind == "modulus_GPa" || ta[i].kind == "frf_peak_Hz";
      ramp_targets += ramp_only ? 1 : 0;
      if (ramp_only) worst_ramp = std::max(worst_ramp, rel);
      worst_target = std::max(worst_target, rel);
      EXPECT_EQ(rel, 0.0) << "point " << point << ", " << ta[i].label;
    }
  }
  EXPECT_EQ(ramp_targets, 4);  // the modulus and the first resonance at both points
  std::printf(
      "objective runs and ramps, lanes vs scalar: residuals %.3g %%, ramp-only targets "
      "%.3g, any target %.3g (relative)\n",
      worst, worst_ramp, worst_target);
}

}  // namespace
