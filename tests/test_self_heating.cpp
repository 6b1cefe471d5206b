// Self-heating (issue 9, item 1): the lumped thermal network against its analytic limits,
// its energy balance, and the coupled run (losses in = heat stored + heat out).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/self_heating.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace {

gmasim::ThermalNetworkModel network() {
  return gmasim::load_model("").thermal_network;  // the defaults of [thermal_network]
}

TEST(ThermalNetwork, OneNodeLimitIsTheFirstOrderLag) {
  // Internal conductances far above the ambient one: one node of capacity C_tot cooled by
  // G_ha, T(t) = T_a + P/G_ha (1 - exp(-t G_ha / C_tot)).
  auto n = network();
  n.G_coil_rods_W_per_K = n.G_coil_housing_W_per_K = n.G_rods_housing_W_per_K = 1e5;
  const double C = n.coil_C_J_per_K + n.rods_C_J_per_K + n.housing_C_J_per_K;
  const double G = n.G_housing_ambient_W_per_K, P = 10.0, Ta = 25.0, tau = C / G;
  gmasim::NodeTemperatures T{Ta, Ta, Ta};
  const double dt = tau / 20000.0;
  for (int k = 0; k < 20000; ++k) gmasim::thermal_network_step(n, T, P, 0.0, Ta, dt);
  const double exact = Ta + P / G * (1.0 - std::exp(-1.0));
  // Backward Euler's error at 20000 steps per tau: ~ (P/G) e^-1 / 2 / 20000 = 1.6e-4 K.
  EXPECT_NEAR(T.housing_C, exact, 2e-3);
  EXPECT_NEAR(T.coil_C, T.housing_C, 1e-3);
}

TEST(ThermalNetwork, ConvergesToTheSteadyStateAndConservesEnergy) {
  const auto n = network();
  const double Pc = 12.0, Pr = 0.5, Ta = 20.0;
  gmasim::NodeTemperatures T{Ta, Ta, Ta};
  const gmasim::NodeTemperatures T0 = T;
  double out = 0.0, in = 0.0;
  const double dt = 5.0;
  for (int k = 0; k < 20000; ++k) {
    out += gmasim::thermal_network_step(n, T, Pc, Pr, Ta, dt);
    in += (Pc + Pr) * dt;
  }
  const auto ss = gmasim::thermal_steady_state(n, Pc, Pr, Ta);
  EXPECT_NEAR(T.coil_C, ss.coil_C, 1e-6);
  EXPECT_NEAR(T.rods_C, ss.rods_C, 1e-6);
  EXPECT_NEAR(T.housing_C, ss.housing_C, 1e-6);
  // At steady state every watt leaves through the housing: T_h - T_a = P / G_ha.
  EXPECT_NEAR(ss.housing_C - Ta, (Pc + Pr) / n.G_housing_ambient_W_per_K, 1e-9);
  EXPECT_GT(ss.coil_C, ss.rods_C);  // the coil carries the copper loss
  EXPECT_NEAR(in - gmasim::stored_heat_J(n, T, T0) - out, 0.0, 1e-9 * in);
}

TEST(ThermalNetwork, BackwardEulerIsFirstOrder) {
  const auto n = network();
  auto run = [&](int steps) {
    gmasim::NodeTemperatures T{20, 20, 20};
    for (int k = 0; k < steps; ++k)
      gmasim::thermal_network_step(n, T, 15.0, 0.2, 20.0, 600.0 / steps);
    return T.rods_C;
  };
  const double ref = run(64000);
  const double e1 = std::fabs(run(100) - ref), e2 = std::fabs(run(200) - ref);
  EXPECT_NEAR(e1 / e2, 2.0, 0.1);
}

TEST(ThermalNetwork, CopperResistanceLaw) {
  const auto n = network();
  EXPECT_DOUBLE_EQ(gmasim::coil_resistance_ohm(n, 20.0, 20.0), n.coil_resistance_ohm);
  EXPECT_NEAR(gmasim::coil_resistance_ohm(n, 20.0, 120.0),
              n.coil_resistance_ohm * (1.0 + 100.0 * n.coil_alpha_per_K), 1e-12);
}

gmasim::SimulationSettings heated(double periods) {
  gmasim::SimulationSettings s;
  s.waveform = gmasim::biased_sine(8.0, 10.0, -3.0);
  s.periods = periods;
  s.dt_s = 5e-5;
  s.record_every = 50;
  s.self_heating.enabled = true;
  return s;
}

TEST(SelfHeating, EnergyBalanceAndCopperLossOfTheCoupledRun) {
  // Small capacities so that 3 s of operation heat the actuator by tens of kelvin.
  const gmasim::ModelSpec spec = gmasim::apply_assignments(
      gmasim::builtin_model_spec(), {"thermal_network.coil_heat_capacity_J_per_K=2",
                                     "thermal_network.rod_specific_heat_J_per_kg_K=20",
                                     "thermal_network.housing_heat_capacity_J_per_K=4",
                                     "thermal_network.coil_to_rods_W_per_K=5"});
  const gmasim::Model m = gmasim::compile(spec);
  const gmasim::SimulationSettings s = heated(60.0);
  const gmasim::Result r = gmasim::simulate(m, s);
  ASSERT_FALSE(r.diverged) << r.error;
  // losses in = heat stored + heat out (issue: within 1 %; observed ~1e-13 relative).
  ASSERT_GT(r.energy_in_J, 10.0);
  EXPECT_NEAR(r.energy_in_J, r.energy_stored_J + r.energy_out_J, 1e-9 * r.energy_in_J);
  // Independent of the bookkeeping: the heat out is the integral of G_ha (T_h - T_a).
  const auto& h = r.heating;
  const auto& t = h.column("t_s");
  const auto& Th = h.column("housing_C");
  double out = 0.0;
  for (std::size_t k = 1; k < h.rows(); ++k)
    out += m.thermal_network.G_housing_ambient_W_per_K * (Th[k] - 20.0) * (t[k] - t[k - 1]);
  EXPECT_NEAR(out, r.energy_out_J, 1e-9 * std::max(1.0, out));
  // Copper loss of the first thermal step: I_rms^2 R at 20 degC, I_rms^2 = 1 + 4^2/2 = 9 A^2
  // (whole periods of the biased sine), to the trapezoid rule's error.
  EXPECT_NEAR(h.column("P_copper_W")[1], 9.0 * m.thermal_network.coil_resistance_ohm, 1e-6);
  // The rods heat and the stroke drops.
  const std::size_t n = h.rows() - 1;
  EXPECT_GT(h.column("rods_C")[n], 30.0);
  EXPECT_LT(h.column("stroke_um")[n], h.column("stroke_um")[2] - 0.5);
  EXPECT_GT(h.column("P_eddy_W")[n], 0.0);
  EXPECT_GT(h.column("P_hysteresis_W")[n], 0.0);
}

TEST(SelfHeating, HugeCapacitiesLeaveTheRunUnchanged) {
  const gmasim::ModelSpec spec = gmasim::apply_assignments(
      gmasim::builtin_model_spec(), {"thermal_network.coil_heat_capacity_J_per_K=1e12",
                                     "thermal_network.rod_specific_heat_J_per_kg_K=1e14",
                                     "thermal_network.housing_heat_capacity_J_per_K=1e12"});
  const gmasim::Model m = gmasim::compile(spec);
  gmasim::SimulationSettings s = heated(3.0);
  const gmasim::Result hot = gmasim::simulate(m, s);
  s.self_heating.enabled = false;
  const gmasim::Result cold = gmasim::simulate(m, s);
  ASSERT_EQ(hot.series.rows(), cold.series.rows());
  const auto& a = hot.series.column("y_um");
  const auto& b = cold.series.column("y_um");
  double worst = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) worst = std::max(worst, std::fabs(a[k] - b[k]));
  EXPECT_LT(worst, 1e-6);
}

TEST(SelfHeating, RefusesAThermalStepLongerThanTheNetworkCanFollow) {
  const gmasim::ModelSpec spec = gmasim::apply_assignments(
      gmasim::builtin_model_spec(), {"thermal_network.coil_heat_capacity_J_per_K=0.01"});
  const gmasim::Model m = gmasim::compile(spec);
  gmasim::SimulationSettings s = heated(2.0);
  try {
    (void)gmasim::simulate(m, s);
    ADD_FAILURE() << "accepted";
  } catch (const gmasim::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fastest time constant"), std::string::npos) << e.what();
  }
  s = heated(2.0);
  s.self_heating.ambient_C = 1e300;
  EXPECT_THROW((void)gmasim::simulate(gmasim::load_model(""), s), gmasim::InputError);
}

}  // namespace
