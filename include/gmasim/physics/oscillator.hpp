// Eq. (15), one law: the update of one oscillator row over a time step, which step() calls for
// every rod (a physics law, below the model: docs/layers.md). The law itself, over the number
// type, is gmasim/physics/laws-inl.h (oscillator_propagator, oscillator_step, base_excited_step);
// here its scalar conveniences. The chain's modes and the small-signal linearisation, which take
// a Model, are in gmasim/mechanics/mechanics.hpp.
#pragma once

#include "gmasim/physics/laws.hpp"

namespace gmasim::physics {

inline OscillatorPropagator oscillator_propagator(double tau, double delta) {
  ExpPoint none = kNoExpPoint;
  return oscillator_propagator(tau, delta, none);
}

inline void oscillator_step(double m, double c, double k, double F0, double F1, double h, double &x,
                            double &v) {
  ExpPoint none = kNoExpPoint;
  oscillator_step(m, 1.0 / m, c, k, F0, F1, h, x, v, none);
}

}  // namespace gmasim::physics
