// Self-heating: the lumped thermal network and the loss laws (docs/model.md, "Self-heating").
#include "gmasim/model/self_heating.hpp"

#include <Eigen/Dense>
#include <algorithm>

#include "gmasim/physics/magnetic.hpp"

namespace gmasim {
namespace {

// Conductance matrix G (W/K) of the three nodes and the ambient coupling vector.
Eigen::Matrix3d conductance(const ThermalNetworkModel& n) {
  const double gcr = n.G_coil_rods_W_per_K, gch = n.G_coil_housing_W_per_K,
               grh = n.G_rods_housing_W_per_K, gha = n.G_housing_ambient_W_per_K;
  Eigen::Matrix3d G;
  G << gcr + gch, -gcr, -gch,  //
      -gcr, gcr + grh, -grh,   //
      -gch, -grh, gch + grh + gha;
  return G;
}

}  // namespace

double coil_resistance_ohm(const ThermalNetworkModel& n, double T_ref_C, double coil_C) {
  return n.coil_resistance_ohm * (1.0 + n.coil_alpha_per_K * (coil_C - T_ref_C));
}

double thermal_network_step(const ThermalNetworkModel& n, NodeTemperatures& T, double P_coil_W,
                            double P_rods_W, double ambient_C, double dt_s) {
  // (C/dt + G) T+ = C/dt T + P + g_a T_a e_h
  const Eigen::Vector3d C(n.coil_C_J_per_K, n.rods_C_J_per_K, n.housing_C_J_per_K);
  Eigen::Matrix3d A = conductance(n);
  A.diagonal() += C / dt_s;
  const Eigen::Vector3d T0(T.coil_C, T.rods_C, T.housing_C);
  Eigen::Vector3d rhs = C.cwiseProduct(T0) / dt_s;
  rhs(0) += P_coil_W;
  rhs(1) += P_rods_W;
  rhs(2) += n.G_housing_ambient_W_per_K * ambient_C;
  const Eigen::Vector3d T1 = A.partialPivLu().solve(rhs);
  T = {T1(0), T1(1), T1(2)};
  return n.G_housing_ambient_W_per_K * (T1(2) - ambient_C) * dt_s;
}

NodeTemperatures thermal_steady_state(const ThermalNetworkModel& n, double P_coil_W,
                                      double P_rods_W, double ambient_C) {
  Eigen::Matrix3d G = conductance(n);
  const Eigen::Vector3d P(P_coil_W, P_rods_W, n.G_housing_ambient_W_per_K * ambient_C);
  const Eigen::Vector3d T = G.partialPivLu().solve(P);
  return {T(0), T(1), T(2)};
}

double stored_heat_J(const ThermalNetworkModel& n, const NodeTemperatures& T,
                     const NodeTemperatures& T0) {
  return n.coil_C_J_per_K * (T.coil_C - T0.coil_C) + n.rods_C_J_per_K * (T.rods_C - T0.rods_C) +
         n.housing_C_J_per_K * (T.housing_C - T0.housing_C);
}

double fastest_time_constant_s(const ThermalNetworkModel& n) {
  const Eigen::Matrix3d G = conductance(n);
  return std::min(
      {n.coil_C_J_per_K / G(0, 0), n.rods_C_J_per_K / G(1, 1), n.housing_C_J_per_K / G(2, 2)});
}

}  // namespace gmasim
