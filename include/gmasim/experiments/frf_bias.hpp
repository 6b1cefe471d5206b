// settle_at_bias (gmasim/experiments/experiments.hpp) in its two parts, for a caller that makes
// many quasi-static ramps together (identify: make_states in SIMD lanes,
// gmasim/simulate/lanes.hpp):
//   settle_at_bias(m, c, I, b) == settle_at_bias_from(m, c, make_state(m, bias_ramp_conditions(m,
//   c, b), I), I, b)
// bit for bit (src/experiments/frf_bias.cpp); and settle_at_bias_from itself in two, for a
// caller that runs the DC settling in lanes (identify, beside its sine targets):
//   State s = bias_settling_start(m, c, ramped, I, b);
//   run_loop(m, c, s, bias_settling_grid(s), HeldCurrent{I});  s.t_s = 0;
// is settle_at_bias_from(m, c, ramped, I, b), bit for bit.
#pragma once

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/simulate/run_loop.hpp"

namespace gmasim {

// The conditions of settle_at_bias's ramp: c, or in the consistent magnetic state with the
// anhysteretic bias, c with every rod's law reduced to its anhysteretic curve (JA: c = 1).
Conditions bias_ramp_conditions(const Model& m, const Conditions& c, BiasState bias_state);

// The rest of settle_at_bias from the state its ramp left (make_state at bias_A under
// bias_ramp_conditions): the anhysteretic hold or fixed point, then the DC settling at bias_A.
State settle_at_bias_from(const Model& m, const Conditions& c, State ramped, double bias_A,
                          BiasState bias_state);

// settle_at_bias_from up to its DC settling: the ramped state held on the anhysteretic curves
// (the consistent reading), or the printed reading's anhysteretic fixed point.
State bias_settling_start(const Model& m, const Conditions& c, State ramped, double bias_A,
                          BiasState bias_state);
// The DC settling's grid from that state (its time on): steps of 10 us over 20 of its rods'
// largest eddy time constant, at least 10 ms.
StepGrid bias_settling_grid(const State& start);

// run_frf's linearised markers over its default band at a settled bias state of conditions c
// (linear_frf_markers(m, T, bias_A) with the state settle_at_bias gives there).
LinearFrfMarkers linear_frf_markers_at(const Model& m, const Conditions& c, const State& settled);

}  // namespace gmasim
