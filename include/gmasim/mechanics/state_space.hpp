// The linearised plant as a state space (issue 40 item 1; docs/experiments.md, "The plant as a
// state space"): SmallSignalModel's equations (gmasim/mechanics/mechanics.hpp) written as
//   x' = A x + B u,  y = C x + D u,   u = the coil current's change dI [A],
// with named states in SI units, for a control engineer's tools (gmasim linearize: JSON, CSV and
// a MATLAB v5 .mat; Python: gmasim.linearize -> scipy.signal.StateSpace). Its transfer function
// C (sI - A)^-1 B + D is SmallSignalModel::response's, by construction of the same equations
// (tests/test_state_space.cpp holds them equal).
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "gmasim/mechanics/mechanics.hpp"
#include "gmasim/model/model.hpp"

namespace gmasim {

struct StateSpace {
  double temperature_C = 0, bias_A = 0;
  int n_states = 0, n_outputs = 0;
  // Row-major: A n x n, B n x 1, C n_outputs x n, D n_outputs x 1.
  std::vector<double> A, B, C, D;
  std::vector<std::string> states, state_units;    // "rod1_H" [A/m], "rod1_x" [m], ...
  std::vector<std::string> outputs, output_units;  // "y" [m] (the sensor), "B" [T]
  std::string input = "current", input_unit = "A";
  // Where the blocks are: the rods' magnetic states (dH, or the lagged dH_c in the printed
  // reading), their displacements and velocities, then the sensor mount's two states (if any).
  std::string magnetic_state;  // "dH: eq. (7)'s eddy lag in the rods' port equations", ...
  // C (sI - A)^-1 B + D at s = j 2 pi f, for output `out`.
  std::complex<double> response(double f_Hz, int out = 0) const;
  // -C A^-1 B + D for output `out` (the small-signal DC gain).
  double dc_gain(int out = 0) const;
  // Eigenvalues of A [1/s], sorted by imaginary part then real part.
  std::vector<std::complex<double>> poles() const;
  // The finite transmission zeros of output `out` [1/s]: the eigenvalues of its zero dynamics
  // (A - B C A^r / (C A^(r-1) B) on ker [C; ...; C A^(r-1)], r the relative degree).
  std::vector<std::complex<double>> zeros(int out = 0) const;

  // The plant split at the sensor mount (issue 40, item 1), so that another sensor model can
  // take the mount's place: blocks[0] is the stack (input the current's change [A]; outputs
  // "y_stack" [m], the stack's displacement of eq. 20, "q" [m], the mount's base -- the housing's
  // recoil, or y_stack when the probe rides on the output -- and "B" [T] when this plant has it);
  // blocks[1] the mount (input q [m]; output "dy" [m], the reading's share: z - q on the recoil,
  // z on the output; states "probe_z" [m] and "probe_zeta" = z' + (c/m)(z - q) [m/s]), absent
  // without a mount. `interconnection` says how they give y: "y = y_stack + dy" (recoil),
  // "y = dy" (on the output) or "y = y_stack" (no mount). Empty for a block itself.
  std::vector<StateSpace> blocks;
  std::string interconnection;
  // y of the blocks put together at f_Hz (interconnection): equal to response(f_Hz, 0).
  std::complex<double> blocks_response(double f_Hz) const;
};

// The state space of L; m gives the rods' names and the induction coil's rods. The output "B"
// (the induction coil's flux density, eq. 20's sensor) is given in the consistent magnetic state,
// where a rod branch's flux is A mu0 (H + M). Throws InputError if a rod has no eddy lag
// (kappa or tau 0: its field is then algebraic, not a state).
StateSpace state_space(const Model& m, const SmallSignalModel& L);

}  // namespace gmasim
