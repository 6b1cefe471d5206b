// settle_at_bias (gmasim/experiments/experiments.hpp) in its two parts, for a caller that makes
// many quasi-static ramps together (identify: make_states in SIMD lanes,
// gmasim/simulate/lanes.hpp):
//   settle_at_bias(m, c, I, b) == settle_at_bias_from(m, c, make_state(m, bias_ramp_conditions(m,
//   c, b), I), I, b)
// bit for bit (src/experiments/frf_bias.cpp).
#pragma once

#include "gmasim/experiments/experiments.hpp"

namespace gmasim {

// The conditions of settle_at_bias's ramp: c, or in the consistent magnetic state with the
// anhysteretic bias, c with every rod's law reduced to its anhysteretic curve (JA: c = 1).
Conditions bias_ramp_conditions(const Model& m, const Conditions& c, BiasState bias_state);

// The rest of settle_at_bias from the state its ramp left (make_state at bias_A under
// bias_ramp_conditions): the anhysteretic hold or fixed point, then the DC settling at bias_A.
State settle_at_bias_from(const Model& m, const Conditions& c, State ramped, double bias_A,
                          BiasState bias_state);

// run_frf's linearised markers over its default band at a settled bias state of conditions c
// (linear_frf_markers(m, T, bias_A) with the state settle_at_bias gives there).
LinearFrfMarkers linear_frf_markers_at(const Model& m, const Conditions& c, const State& settled);

}  // namespace gmasim
