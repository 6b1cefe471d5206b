// The coil's incremental inductance at a DC bias (issue 39 item 1; gmasim/experiments/
// experiments.hpp): reported by `gmasim model show`, not used by the step (the step drives the
// circuit with the current, eq. 22-23, and needs no inductance).
#include <algorithm>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/simulate/run_loop.hpp"

namespace gmasim {
namespace {

// The coil's flux linkage, sum over the branches of N_b phi_b [Wb-turns].
double flux_linkage_Wb(const Model& m, const State& s) {
  double psi = 0.0;
  for (std::size_t b = 0; b < m.circuit.branches.size(); ++b)
    psi += m.circuit.branches[b].coil_turns * s.circuit.phi[b];
  return psi;
}

// The state at rest after the current has stepped from the bias to bias + dI: held until the
// rods' eddy lag (eq. 7) has died out (40 of the slowest tau at the bias, at least 2 ms), every
// branch's flux solved (the energy switch asks the step for all of them).
double linkage_after_step(const Model& m, const Conditions& c, State s, double current_A,
                          double tau_max_s) {
  s.energy.enabled = true;
  const double h = std::clamp(tau_max_s / 50.0, 1e-7, 10e-6);
  run_loop(m, c, s, StepGrid::covering(s.t_s, std::max(40.0 * tau_max_s, 2e-3), h, "inductance"),
           HeldCurrent{current_A});
  return flux_linkage_Wb(m, s);
}

}  // namespace

CoilInductance coil_inductance(const Model& m, double temperature_C, double bias_A,
                               double delta_A) {
  if (!(delta_A > 0.0))
    throw InputError("coil_inductance: the current step must be > 0 A, got " +
                     std::to_string(delta_A));
  CoilInductance out;
  out.temperature_C = temperature_C;
  out.bias_A = bias_A;
  out.delta_A = delta_A;
  const Conditions c = make_conditions(m, temperature_C);
  const State bias = settle_at_bias(m, c, bias_A, BiasState::Anhysteretic);
  double tau_max = 0.0;
  for (const auto& r : bias.rods) tau_max = std::max(tau_max, r.tau_s);
  // Central differences over +-delta and +-2 delta, Richardson-combined: the law's
  // irreversible part, M_irr - M_an = O(dH) on the minor loop, moves the linkage by O(dI^2) with
  // the step's sign (dM_irr = (M_an - M_irr) dH / k), which the central difference leaves at O(dI)
  // and the combination 2 L(delta) - L(2 delta) removes.
  auto central = [&](double d) {
    return (linkage_after_step(m, c, bias, bias_A + d, tau_max) -
            linkage_after_step(m, c, bias, bias_A - d, tau_max)) /
           (2.0 * d);
  };
  const double L1 = central(delta_A), L2 = central(2.0 * delta_A);
  out.inductance_H = 2.0 * L1 - L2;
  out.first_order_H = L1;
  out.linkage_Wb = linkage_after_step(m, c, bias, bias_A, tau_max);
  return out;
}

}  // namespace gmasim
