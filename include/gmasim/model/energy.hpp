// The energy ledgers (issue 18; docs/model.md, "Energy ledgers"). Each storing or
// dissipating element books its own term from its own law; the residual of a ledger is a
// check of the integrator, never a way to compute a term.
//
// Magnetic ledger (the circuit of eq. 23 with the rods of the consistent reading):
//   coil work  sum_b N_b int i dphi_b  +  magnet work  sum_b F_pm,b^T int dphi_b
//     = change of stored energy (the fixed reluctances 1/2 R phi^2, each rod's series
//       reluctance 1/2 R_s phi^2, each rod's material l A (mu0 H^2/2 + Phi_JA))
//     + hysteresis  l A int (1 - c) mu0 (H_e - H_an(M_irr)) dM_irr   (per rod)
//     + eddy        l A int kappa (dB/dt)^2 dt                         (per rod)
// Mechanical ledger (each rod's oscillator of eq. 15):
//   int F dx  +  stiffness work  sum 1/2 (K_new - K_old) x^2   (the Delta-E effect)
//     = change of kinetic 1/2 m v^2 and elastic 1/2 K x^2 energy + damping int c v^2 dt.
// The magnetostrictive coupling is one-way (the rods' dynamic stress does not act back on
// their magnetisation), so the mechanical input is not drawn from the coil: the balance
// reports it as the coupling power.
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace gmasim {

struct Model;
struct Conditions;
struct State;

// Per-rod running sums [J], advanced by step() while EnergyAccumulators::enabled.
struct RodEnergy {
  double material_work_J = 0;   // l A int H dB (trapezoid over each step)
  double hysteresis_J = 0;      // l A physics::ja_step_dissipation over each step
  double eddy_J = 0;            // l A int kappa (dB/dt)^2 dt (consistent); printed: (Hc - H) dB
  double force_work_J = 0;      // int F dx over the exact oscillator update (Gauss-Legendre)
  double stiffness_work_J = 0;  // 1/2 (K_new - K_old) x^2 at each step boundary
  double damping_J = 0;         // int c v^2 dt (eq. 25's c + c_lr), Gauss-Legendre
};

// Model-wide running sums [J] and the step's coil EMF; phi_prev_Wb holds every branch's flux
// at the start of the step (sized once by make_state).
struct EnergyAccumulators {
  bool enabled = false;   // book every step (solves every branch of the circuit: slower)
  double coil_J = 0;      // sum over coil branches of N_b int i dphi_b (trapezoid in i)
  double magnet_J = 0;    // sum over magnet branches of F_pm,b^T int dphi_b
  double coil_emf_V = 0;  // sum N_b dphi_b/dt over the last step (ledger steps only)
  std::vector<double> phi_prev_Wb;
};

// The stored energies of a state [J] (state functions).
struct StoredEnergy {
  double circuit_J = 0;   // 1/2 R_b phi_b^2 over the fixed-reluctance branches
  double series_J = 0;    // 1/2 R_s phi^2 over the rods' series reluctances (consistent)
  double material_J = 0;  // l A (mu0 H^2/2 + Phi_JA) over the rods
  double kinetic_J = 0;   // 1/2 m v^2 of the rods' oscillators
  double elastic_J = 0;   // 1/2 K x^2 of the rods' oscillators (K of the last step)
};

// Everything a ledger needs at one instant: the running sums and the stored energies. Taken
// after a step that booked (the circuit's branch fluxes are then all solved).
struct EnergySnapshot {
  double t_s = 0;
  double coil_J = 0, magnet_J = 0;
  std::vector<RodEnergy> rods;
  StoredEnergy stored;
};
EnergySnapshot energy_snapshot(const Model& m, const Conditions& c, const State& s);

// The two ledgers between two snapshots of one run at one temperature [J].
struct EnergyBalance {
  double duration_s = 0;
  // magnetic
  double coil_J = 0, magnet_J = 0;
  double d_circuit_J = 0, d_series_J = 0, d_material_J = 0;
  double hysteresis_J = 0, eddy_J = 0;
  std::vector<double> rod_hysteresis_J, rod_eddy_J;
  double magnetic_residual_J = 0;    // input - (stored change + losses)
  double magnetic_residual_rel = 0;  // |residual| / max(|input|, gross flows, 1e-3 stored)
  // mechanical
  double force_work_J = 0, stiffness_work_J = 0;
  double d_kinetic_J = 0, d_elastic_J = 0, damping_J = 0;
  double mechanical_residual_J = 0;
  double mechanical_residual_rel = 0;  // same scale rule as the magnetic ledger
  // The mechanical input the one-way model does not draw from the coil, over the magnetic
  // input: (force + stiffness work) / (coil + magnet work).
  double coupling_fraction = 0;
  double losses_J() const { return hysteresis_J + eddy_J + damping_J; }
};
EnergyBalance energy_balance(const EnergySnapshot& from, const EnergySnapshot& to);

// Books one step (called by step() when s.energy.enabled; the start values are the state
// before the step).
struct StepStart {
  double H, Hc, M, Mirr, B, x, v, F, K;
};
void book_step_energy(const Model& m, const Conditions& c, State& s, const StepStart* start,
                      double current0_A, double current1_A, double h_s);

}  // namespace gmasim
