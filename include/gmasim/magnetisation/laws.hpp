// The magnetisation-law seam (issue 21; docs/layers.md, "Adding a magnetisation law"). A law
// is a struct of static functions (gmasim/magnetisation/jiles_atherton.hpp is the reference):
//   init_state            its per-rod state at make_state (demagnetised)
//   trial, commit         a move of the field H0 -> H1: M at H1 and dM/dH (the consistent
//                         state's Newton solve), without / with changing the state
//   reversible_susceptibility   dM/dH with the irreversible state held (the FRF)
//   step_dissipation, stored_energy_density   the ledgers (gmasim/model/energy.hpp)
//   ode_*                 the law as an ODE for the RK4 reference
//   reduce_to_anhysteretic, anhysteretic_magnetisation, hold_anhysteretic
//                         the FRF's anhysteretic bias state
//   characteristic_field_A_per_m (and _name), loop_width_key
//                         identify's field-record check and track's plant mismatches
// Its constants land in RodModel through its parameter rows and reach RodConditions through
// its temperature laws (src/model/magnetisation/<law>.cpp). The step is compiled once per
// law (step_law<Law>); a run dispatches once, by with_magnetisation_law, not per step.
// Registration: the enum (law_id.hpp), the option word (src/model/parameters.cpp) and the
// case below.
#pragma once

#include <utility>

#include "gmasim/magnetisation/jiles_atherton.hpp"
#include "gmasim/magnetisation/preisach.hpp"

namespace gmasim {

// Calls f(Law{}) for the law the model selects (one branch, outside any time loop).
template <class F>
decltype(auto) with_magnetisation_law(MagnetisationLaw law, F&& f) {
  switch (law) {
    case MagnetisationLaw::Preisach:
      return std::forward<F>(f)(PreisachLaw{});
    case MagnetisationLaw::JilesAtherton:
      break;
  }
  return std::forward<F>(f)(JilesAthertonLaw{});
}

}  // namespace gmasim
