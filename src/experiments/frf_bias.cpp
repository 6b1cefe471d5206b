// gmasim frf's bias point (Fig. 15): the actuator settled at a DC bias current, in the
// anhysteretic state an AC shake-down leaves or on its virgin curve (settle_at_bias,
// gmasim/experiments/experiments.hpp). docs/experiments.md, "Frequency response".
#include "gmasim/experiments/frf_bias.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/step_stages.hpp"
#include "gmasim/simulate/run_loop.hpp"

namespace gmasim {
namespace {

using namespace physics;

constexpr double kSettleDt_s = 10e-6;

// DC steps of kSettleDt_s at current I for duration_s (rounded to whole steps), from s.t_s.
void run_dc(const Model& m, const Conditions& c, State& s, double I, double duration_s) {
  run_loop(m, c, s, StepGrid::covering(s.t_s, duration_s, kSettleDt_s, "DC settling"),
           HeldCurrent{I});
}

// The printed reading: put each rod on its anhysteretic curve, M_irr = M = M_an(H + alpha M),
// at the field it sees; the circuit then moves the field (mu depends on M), so repeat until the
// fixed point holds, with DC steps in between that let H, the circuit and the mechanics follow.
template <class Law>
void anhysteretic_fixed_point(const Model& m, const Conditions& c, State& s, double bias_A) {
  double tau_max = 0.0;
  for (const auto& r : s.rods) tau_max = std::max(tau_max, r.tau_s);
  for (int it = 0; it < 60; ++it) {
    double change = 0.0;
    for (std::size_t i = 0; i < s.rods.size(); ++i) {
      const auto& rc = c.rods[i];
      auto& r = s.rods[i];
      const double M = Law::anhysteretic_magnetisation(rc, r);
      change = std::max(change, Law::hold_anhysteretic(rc, r, M) / rc.MsT_mag);
      hold_history(r);
    }
    run_dc(m, c, s, bias_A, std::max(5.0 * tau_max, 1e-3));
    if (change < 1e-10) break;
  }
}

// Whether settle_at_bias ramps on the anhysteretic curves (the consistent reading) instead of
// the virgin curve.
bool anhysteretic_ramp(const Model& m, BiasState bias_state) {
  return bias_state == BiasState::Anhysteretic &&
         m.options.magnetic_state == MagneticState::Consistent;
}

template <class Law>
Conditions ramp_conditions(const Model& m, const Conditions& c, BiasState bias_state) {
  Conditions anh = c;
  if (anhysteretic_ramp(m, bias_state))
    for (auto& rc : anh.rods) Law::reduce_to_anhysteretic(rc);
  return anh;
}

// settle_at_bias_from up to its DC settling: the state the settling starts from.
template <class Law>
State settling_start(const Model& m, const Conditions& c, State s, double bias_A,
                     BiasState bias_state) {
  if (anhysteretic_ramp(m, bias_state)) {
    // The consistent reading: s is the quasi-static ramp of make_state with every rod's JA law
    // reduced to its anhysteretic curve, M = M_an(H + alpha M) (c = 1, eq. 9; ramp_conditions),
    // so that the circuit, the fields and the magnetisations are solved together (the fixed
    // point above does not converge when a rod's series reluctance makes its branch nearly
    // flux-driven). Then M_irr = M_an = M, where the full law of eq. (9) holds the same state
    // (Preisach: the hysterons' coercive fields shrunk, then the AC-demagnetised state of the
    // full law).
    for (std::size_t i = 0; i < s.rods.size(); ++i) {
      auto& r = s.rods[i];
      (void)Law::hold_anhysteretic(c.rods[i], r, r.M_A_per_m);
      hold_history(r);
    }
  } else if (bias_state == BiasState::Anhysteretic) {  // s: the virgin curve, static equilibrium
    anhysteretic_fixed_point<Law>(m, c, s, bias_A);
  }
  return s;
}

}  // namespace

Conditions bias_ramp_conditions(const Model& m, const Conditions& c, BiasState bias_state) {
  return with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
    return ramp_conditions<decltype(law)>(m, c, bias_state);
  });
}

State bias_settling_start(const Model& m, const Conditions& c, State ramped, double bias_A,
                          BiasState bias_state) {
  return with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
    return settling_start<decltype(law)>(m, c, std::move(ramped), bias_A, bias_state);
  });
}

StepGrid bias_settling_grid(const State& start) {
  // Let H (eddy lag), M and the oscillators come to rest at the bias.
  double tau_max = 0.0;
  for (const auto& r : start.rods) tau_max = std::max(tau_max, r.tau_s);
  return StepGrid::covering(start.t_s, std::max(20.0 * tau_max, 10e-3), kSettleDt_s, "DC settling");
}

State settle_at_bias_from(const Model& m, const Conditions& c, State ramped, double bias_A,
                          BiasState bias_state) {
  State s = bias_settling_start(m, c, std::move(ramped), bias_A, bias_state);
  run_loop(m, c, s, bias_settling_grid(s), HeldCurrent{bias_A});
  s.t_s = 0.0;
  return s;
}

State settle_at_bias(const Model& m, const Conditions& c, double bias_A, BiasState bias_state) {
  const Conditions ramp = bias_ramp_conditions(m, c, bias_state);
  return settle_at_bias_from(m, c, make_state(m, ramp, bias_A), bias_A, bias_state);
}

}  // namespace gmasim
