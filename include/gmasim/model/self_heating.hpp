// Self-heating (issue 9, item 1; docs/model.md, "Self-heating"): a lumped thermal network
// (coil, rods, housing; ambient as a boundary) driven by the losses the electromagnetic model
// computes (copper I^2 R in the coil; eddy-current and hysteresis losses in the rods).
// Temperature becomes state on a slower clock: simulate() advances the network once per
// thermal step and recomputes the Conditions at the new rod temperature.
#pragma once

#include "gmasim/model/model.hpp"

namespace gmasim {

struct NodeTemperatures {
  double coil_C = 20, rods_C = 20, housing_C = 20;
};

// Copper law: R(T) = R_ref (1 + alpha (T - T_ref)) [ohm].
double coil_resistance_ohm(const ThermalNetworkModel& n, double T_ref_C, double coil_C);

// Copper loss of one step, trapezoidal in i^2: 0.5 (i0^2 + i1^2) R dt [J].
inline double copper_loss_J(double i0_A, double i1_A, double R_ohm, double dt_s) {
  return 0.5 * (i0_A * i0_A + i1_A * i1_A) * R_ohm * dt_s;
}

// One backward-Euler step of the network  C dT/dt = P - G (T - ...):
//   C_c T_c' = P_coil - G_cr (T_c - T_r) - G_ch (T_c - T_h)
//   C_r T_r' = P_rods - G_cr (T_r - T_c) - G_rh (T_r - T_h)
//   C_h T_h' =        - G_ch (T_h - T_c) - G_rh (T_h - T_r) - G_ha (T_h - T_a)
// Unconditionally stable; the internal flows cancel exactly, so the heat stored plus the
// heat to ambient equals the heat put in (to rounding). Returns the heat to ambient over
// the step [J]. Allocation-free (a 3x3 solve).
double thermal_network_step(const ThermalNetworkModel& n, NodeTemperatures& T, double P_coil_W,
                            double P_rods_W, double ambient_C, double dt_s);

// The steady state under constant powers (G T = P).
NodeTemperatures thermal_steady_state(const ThermalNetworkModel& n, double P_coil_W,
                                      double P_rods_W, double ambient_C);

// Heat held above a reference state: sum of C_i (T_i - T0_i) [J].
double stored_heat_J(const ThermalNetworkModel& n, const NodeTemperatures& T,
                     const NodeTemperatures& T0);

// The fastest time constant of the network, min over nodes of C_i / (sum of its G) [s]:
// the thermal step must stay below it for accuracy (simulate() refuses a longer one).
double fastest_time_constant_s(const ThermalNetworkModel& n);

}  // namespace gmasim
