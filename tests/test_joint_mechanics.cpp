// Issue 37 item 3, the joints' reading (docs/model.md, "The joints"): options.joint_mechanics =
// "bonded" makes each rod's joint gap g an epoxy bond line of modulus E_j, a compliance
// c_j = g / (E_j A) in series with the rod's l / (E A) (eq. 17). Held here: the law against its
// closed form (and rigid joints against eq. 14 and 17 bit for bit), the step's static deflection
// against the series-spring formula, the energy ledger, and the lanes against the scalar step.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "builtin_models.hpp"
#include "gmasim/model/energy.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/laws.hpp"
#include "gmasim/physics/mechanics.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "lanes_test_util.hpp"

namespace {

using namespace gmasim;

Model bonded() { return gmasim_test::mdma_with_option("options.joint_mechanics", "bonded"); }

physics::RodMechanics mechanics_at(double M, double joint_compliance) {
  const physics::DeltaETerms dE{1.0 / 88e9, 1.5e-11, 2e-3, 5e5, 1e5};
  physics::ExpPoint prestress{};
  return physics::rod_mechanics(M, 1.0 / 7.6e5, dE, 1.0 / 7.6e5, 1.2e-3, 8e6, 4.0 * 8e6 / 1.2e-3,
                                1.1e-4, 1.1e-4 / 0.08, 0.08 / 1.1e-4, joint_compliance, prestress);
}

// The law: rigid joints give eq. (14) and (17) exactly; bonded ones keep the free stroke
// F / k = lambda l and put c_j in series: 1/k = l/(E A) + c_j, F = lambda l k.
TEST(JointMechanics, LawIsTheRodInSeriesWithItsJoints) {
  for (double M : {-5e5, 1e5, 6.5e5}) {
    const physics::RodMechanics rigid = mechanics_at(M, 0.0);
    EXPECT_EQ(rigid.F_N, physics::rod_force(rigid.lambda, rigid.E_Pa, 1.1e-4));
    EXPECT_EQ(rigid.k_rod_N_per_m, rigid.E_Pa * (1.1e-4 / 0.08));
    const double c_j = physics::joint_compliance(5e-4, 3e9, 1.1e-4);  // 1.5e-9 m/N
    const physics::RodMechanics b = mechanics_at(M, c_j);
    EXPECT_EQ(b.E_Pa, rigid.E_Pa);
    EXPECT_EQ(b.lambda, rigid.lambda);
    const double c_rod = 0.08 / (rigid.E_Pa * 1.1e-4);
    EXPECT_NEAR(b.k_rod_N_per_m * (c_rod + c_j), 1.0, 1e-14);
    EXPECT_NEAR(b.compliance_m_per_N / (c_rod + c_j), 1.0, 1e-14);
    EXPECT_NEAR(b.F_N / b.k_rod_N_per_m / (rigid.lambda * 0.08), 1.0, 1e-14);  // free stroke
    EXPECT_LT(b.k_rod_N_per_m, 0.95 * rigid.k_rod_N_per_m);  // c_j is not small here
  }
}

// The step: under a DC current held until the oscillators rest, each rod's deflection is the
// series-spring formula lambda l k_eff / (k_eff + k_load), k_eff = 1 / (l/(E A) + c_j), from the
// rod's own lambda and E and its chain's k_load -- and the joints' compliance is in the chains
// (the rods load one another through it).
TEST(JointMechanics, StaticDeflectionIsTheSeriesSpringFormula) {
  const Model m = bonded();
  ASSERT_EQ(m.options.joint_mechanics, JointMechanics::Bonded);
  const Conditions c = make_conditions(m, 20.0);
  State s = make_state(m, c, 0.0);
  const double h = 2e-6;
  for (long k = 1; k <= 40000; ++k) {  // 80 ms at 2 A: the slowest mode decays in ~5 ms
    step(m, c, s, {k < 1000 ? 2.0 * static_cast<double>(k) / 1000.0 : 2.0, h});
    s.t_s = static_cast<double>(k) * h;
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < s.rods.size(); ++i) {
    const RodConditions& rc = c.rods[i];
    const RodState& r = s.rods[i];
    ASSERT_GT(rc.joint_compliance_m_per_N, 0.0) << m.rods[i].name;
    EXPECT_DOUBLE_EQ(rc.joint_compliance_m_per_N,
                     m.rods[i].joint_gap_m / (m.rods[i].joint_modulus_Pa * rc.area_m2));
    const double k_eff = 1.0 / (rc.length_m / (r.E_Pa * rc.area_m2) + rc.joint_compliance_m_per_N);
    const double want = r.lambda * rc.length_m * k_eff / (k_eff + r.k_load_N_per_m);
    const double e = std::fabs(r.x_m / want - 1.0);
    worst = std::max(worst, e);
    EXPECT_LT(e, 1e-10) << m.rods[i].name;  // observed 7.6e-12 (the printout)
    EXPECT_LT(k_eff, 0.95 * r.E_Pa * rc.area_m2 / rc.length_m) << m.rods[i].name;
  }
  std::printf("bonded joints: static deflection vs series-spring formula %.3g relative\n", worst);
}

// The mechanical ledger closes with the joints' force and stiffness as it does without (the
// step's oscillator is driven by the rod-and-joint element's F and K).
TEST(JointMechanics, MechanicalLedgerCloses) {
  const Model m = bonded();
  const Conditions c = make_conditions(m, 150.0);
  const Waveform w = biased_sine(6.0, 10.0);
  const double h = 1.0 / (10.0 * 10000);
  State s = make_state(m, c, w.current_at(0.0));
  s.energy.enabled = true;
  EnergySnapshot a{};
  for (long k = 1; k <= 30000; ++k) {
    step(m, c, s, {w.current_at(static_cast<double>(k) * h), h});
    s.t_s = static_cast<double>(k) * h;
    if (k == 20000) a = energy_snapshot(m, c, s);
  }
  const EnergyBalance e = energy_balance(a, energy_snapshot(m, c, s));
  EXPECT_LT(e.mechanical_residual_rel, 1e-8);  // observed 1.3e-9
  EXPECT_LT(e.magnetic_residual_rel, 1e-9);    // observed 3.2e-11
  std::printf("bonded joints: ledger residuals mechanical %.3g, magnetic %.3g\n",
              e.mechanical_residual_rel, e.magnetic_residual_rel);
}

// The lanes carry c_j as a rod constant and call the same law: simulate_lanes equals simulate
// bit for bit, as for rigid joints.
TEST(JointMechanics, LanesEqualTheScalarStep) {
  const std::vector<SimulationSettings> set =
      gmasim_test::biased_sine_settings({20.0, 110.0}, {4.0, 8.0}, 50.0, 1);
  EXPECT_EQ(gmasim_test::expect_simulate_lanes_matches(bonded(), set, 0.0), 0.0);
}

}  // namespace
