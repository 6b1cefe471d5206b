// Quantities that follow from a model's geometry and material (issue 39, item 1): derived when
// the model is compiled, so that a user who changes a rod's diameter or length gets the mass
// that goes with it, never the stale one of another design. A value the file gives (or a --set)
// overrides the derivation; it is reported with the derived value beside it, and a warning is
// given when the two differ by more than kDerivedWarnFraction (gmasim/model/validity.hpp,
// model_warnings). The derivations:
//   <rod>.mass_kg = material.density_kg_per_m3 x pi (r_o^2 - r_i^2) x <rod>.length_m
//   thermal_network.coil_resistance_ohm = coil_resistivity_ohm_m x N x coil_mean_turn_length_m
//       / (pi coil_wire_diameter_m^2 / 4), N the turns of every branch that carries a coil (in
//       series: one current), when the winding's wire diameter and mean turn length are given
//   thermal_network.coil_heat_capacity_J_per_K = coil_density_kg_per_m3 x N x
//       coil_mean_turn_length_m x (pi coil_wire_diameter_m^2 / 4) x coil_specific_heat_J_per_kg_K
//       (the winding's copper), under the same condition
//   circuit.reluctances_per_H.<name> = length_m / (mu0 relative_permeability area_m2) of
//       [circuit.reluctance_geometry.<name>], for each such table
#pragma once

#include <string>
#include <vector>

#include "gmasim/model/model.hpp"

namespace gmasim {

inline constexpr double kDerivedWarnFraction = 0.10;

struct DerivedQuantity {
  std::string name;  // the parameter, "rod1.mass_kg"
  double derived;    // its value by the formula
  std::string
      formula;      // "material.density_kg_per_m3 9250 x pi (r_o^2 - r_i^2) 1.374e-04 m^2 x ..."
  bool overridden;  // the spec gives its own value (file or --set)
  double value;     // the spec's value (the derived one unless overridden)
};

// Every derivable parameter of the spec with its derived value; the spec is not changed.
std::vector<DerivedQuantity> derived_quantities(const ModelSpec& spec);

// Writes the derived value into each derivable parameter the spec does not give (line 0, not
// assigned), with the provenance "derived: <formula> = <value>"; the loader and compile() call
// it. Returns the names it derived: their rules are not checked on their own (line 0 would
// name no line), their inputs' are.
std::vector<std::string> apply_derivations(ModelSpec& spec);

}  // namespace gmasim
