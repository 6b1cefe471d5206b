// gmasim frf's bias point (Fig. 15): the actuator settled at a DC bias current, in the
// anhysteretic state an AC shake-down leaves or on its virgin curve (settle_at_bias,
// gmasim/experiments/experiments.hpp). docs/experiments.md, "Frequency response".
#include <algorithm>
#include <cmath>

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

template <class Law>
State settle_law(const Model& m, const Conditions& c, double bias_A, BiasState bias_state) {
  State s;
  if (bias_state == BiasState::Anhysteretic &&
      m.options.magnetic_state == MagneticState::Consistent) {
    // The consistent reading: the quasi-static ramp of make_state with every rod's JA law
    // reduced to its anhysteretic curve, M = M_an(H + alpha M) (c = 1, eq. 9), so that the
    // circuit, the fields and the magnetisations are solved together (the fixed point above
    // does not converge when a rod's series reluctance makes its branch nearly flux-driven).
    // Then M_irr = M_an = M, where the full law of eq. (9) holds the same state (Preisach: the
    // hysterons' coercive fields shrunk, then the AC-demagnetised state of the full law).
    Conditions anh = c;
    for (auto& rc : anh.rods) Law::reduce_to_anhysteretic(rc);
    s = make_state(m, anh, bias_A);
    for (std::size_t i = 0; i < s.rods.size(); ++i) {
      auto& r = s.rods[i];
      (void)Law::hold_anhysteretic(c.rods[i], r, r.M_A_per_m);
      hold_history(r);
    }
  } else {
    s = make_state(m, c, bias_A);  // virgin curve, static equilibrium
    if (bias_state == BiasState::Anhysteretic) anhysteretic_fixed_point<Law>(m, c, s, bias_A);
  }
  double tau_max = 0.0;
  for (const auto& r : s.rods) tau_max = std::max(tau_max, r.tau_s);
  // Let H (eddy lag), M and the oscillators come to rest at the bias.
  run_dc(m, c, s, bias_A, std::max(20.0 * tau_max, 10e-3));
  s.t_s = 0.0;
  return s;
}

}  // namespace

State settle_at_bias(const Model& m, const Conditions& c, double bias_A, BiasState bias_state) {
  return with_magnetisation_law(m.options.magnetisation_law, [&](auto law) {
    return settle_law<decltype(law)>(m, c, bias_A, bias_state);
  });
}

}  // namespace gmasim
