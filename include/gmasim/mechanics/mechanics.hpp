// The mechanics module (docs/layers.md, "The mechanics module"): the actuator's mechanics
// apart from any experiment. The oscillator update of eq. (15) (gmasim/physics/oscillator.hpp,
// called by step()), the modes of the chain of eq. (15) with the sensor mount
// (src/mechanics/modal.cpp), and the small-signal linearisation of the whole actuator (circuit,
// eddy lag, magnetisation law, forces, oscillators) about a settled bias point
// (src/mechanics/linearise.cpp). gmasim frf and the feed-forward design use them.
#pragma once

#include <complex>
#include <vector>

#include "gmasim/model/model.hpp"
#include "gmasim/physics/oscillator.hpp"

namespace gmasim {

// Small-signal model about a settled bias point (docs/experiments.md, "FRF"):
//   dHc = g dI + G dM                      circuit, with the mu(M) feedback of eq. 2-3
//   dH_i = dHc_i / (1 + tau_i s)           eddy lag, eq. 7
//   dM_i = chi_i dH_i                      the law's reversible slope (JA with M_irr pinned:
//                                          c M_an'/(1 - alpha c M_an'), magnetisation/laws.hpp)
//   dF_i = sum_j D_ij dM_j                 force (eq. 11-14) minus dK_i(M) x0_i (eq. 16-18)
//   (m_i s^2 + c_i s + K_i) dx_i = dF_i    eq. 15;  Y = sum_i dx_i
struct SmallSignalModel {
  double temperature_C = 0, bias_A = 0;
  int n = 0;                            // rods
  std::vector<double> g_A_per_m_per_A;  // dHc_i/dI at fixed M
  std::vector<double> G;                // n x n row-major, dHc_i/dM_j at fixed I [-]
  std::vector<double> tau_s;            // eddy time constants
  std::vector<double> chi;              // reversible dM/dH [-]
  std::vector<double> D_N_per_A_per_m;  // n x n row-major, dF_net_i/dM_j [N m/A]
  std::vector<double> mass_kg, damping_N_s_per_m, stiffness_N_per_m;  // eq. 15 diagonal
  std::vector<double> x0_m, M0_A_per_m, H0_A_per_m;                   // the bias point
  double y0_m = 0;
  // Consistent magnetic state (model.hpp, MagneticState): the rods' port equations
  //   l_i (dH_i + kappa_i s dB_i) + sum_j S_ij A_j dB_j = b_i dI,  dB = mu0 (1 + chi) dH,
  // with S (n x n row-major) and b the circuit seen from the rod branches, each rod's own series
  // reluctance R_s (k_f, physics::series_reluctance) on S's diagonal [1/H, A-turns/A].
  bool consistent = false;
  std::vector<double> port_S_per_H, port_b_At_per_A, length_m, kappa_s_m_per_H, area_m2;
  // Sensor mount (model.hpp, SensorMountModel), if any: Y_sensor = Y_stack - u with the probe's
  // deflection u = Q m s^2 / (m s^2 + c s + k), Q = sum recoil_per_x_i X_i the housing's recoil.
  bool sensor_mount = false;
  double sm_mass_kg = 0, sm_stiffness_N_per_m = 0, sm_damping_N_s_per_m = 0;
  bool sm_on_output = false;  // options.sensor_mount_base = output: Y x (c s + k)/(m s^2 + c s + k)
  std::vector<double> recoil_per_x;  // (m_i/2 + m_lr,i) / M_actuator per rod [-]
  // Y(j 2 pi f)/I [m/A].
  std::complex<double> response(double f_Hz) const;
};

// Linearises the settled state s (from settle_at_bias) at current s.current_A.
SmallSignalModel linearise(const Model& m, const Conditions& c, const State& s);

struct Mode {
  double frequency_Hz = 0;         // undamped natural frequency w / 2 pi
  double damped_frequency_Hz = 0;  // f sqrt(1 - zeta^2) (0 if overdamped)
  double damping_ratio = 0;        // classical modal damping zeta
};
// Modes of the rods' chain of eq. (15) at the state (src/mechanics/modal.cpp): M, C, K of
// eq. (16), (24), (25) assembled as full matrices (diagonal for the MDMA), undamped modes
// K v = w^2 M v, classical modal damping zeta = v'Cv / (2 w v'Mv). Sorted by frequency. The
// sensor mount is not part of the chain (its deflection enters SmallSignalModel::response).
std::vector<Mode> mechanical_modes(const Model& m, const Conditions& c, const State& s);

}  // namespace gmasim
