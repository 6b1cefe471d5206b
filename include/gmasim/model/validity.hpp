// Physical validity (issue 19, items 3 and 8; docs/model.md, "Physical validity"): what an
// accepted input may not produce, and where a model may be used.
//
//   check_physical_validity   the guard of the run loop: a state no actuator can reach ends the
//                             run as a DivergenceError naming time, rod and quantity;
//   check_model_validity      a model no actuator can be (a prestress that would crush a rod),
//                             refused by compile();
//   model_warnings            values far outside Terfenol-D's known range (a warning, not a
//                             refusal: a model of another material is allowed);
//   computable_range          where the model's laws can be evaluated at all (make_conditions
//                             refuses outside it and names it);
//   validated_range           where the model was validated ([validity] of the model file);
//                             temperature_warning says when a temperature lies outside it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "gmasim/model/model.hpp"

namespace gmasim {

// The bounds of the guard, per rod, from the model and the conditions (documented in
// docs/model.md, "Physical validity"):
//   |lambda| <= 1.5 lambda_s (1.5 M_s^T / M_s,strain)^2: the largest strain eq. (11) gives
//              (prestress factor <= 1.5) at the largest |M| step() accepts (1.5 M_s^T);
//   |x|      <  l^T, the rod's length: a rod cannot move by more than it is long;
//   |B|      <= mu0 (1.05 max(M_s, M_s^T) + |H|) for the consistent magnetic state (B = mu0
//              (H + M) with |M| <= M_s^T, 5 % for the JA overshoot); the printed reading's
//              phi/A is not a material flux density (docs/model.md, "Magnetic state") and is not
//              bounded.
inline constexpr double kStrainGuardFactor = 1.5 * 1.5 * 1.5;  // 1.5 lambda_s (1.5)^2
inline constexpr double kFluxGuardMsFactor = 1.05;

// Throws DivergenceError(t_s, rod, quantity, value, "beyond the physical bound ...") for the
// first rod whose state breaks a bound. Allocation-free unless it throws; called by the run loop
// after every step (gmasim/simulate/run_loop.hpp) and by the Stepper through it.
void check_physical_validity(const Model& m, const Conditions& c, const State& s, double t_s);

// Terfenol-D's compressive strength is 305-880 MPa (manufacturer data); no rod survives a
// prestress of kMaxPrestress_Pa. compile() refuses a preload above it in any rod, naming
// preload.force_N, the rod and its prestress.
inline constexpr double kMaxPrestress_Pa = 1e9;
void check_model_validity(const Model& m);

// One line per value far outside the known range of Terfenol-D or of an actuator of its kind
// ("<file>:<line>: material.Es_Pa = 1000 Pa: far outside Terfenol-D's known range [1e+10,
// 2e+11] Pa; the results may mean nothing"); empty for the models of models/.
std::vector<std::string> model_warnings(const Model& m);

struct TemperatureRange {
  double min_C = 0.0, max_C = 0.0;
  bool below_curie = false;  // max_C is the Curie temperature itself, which is excluded
};
// The largest interval around reference.T_ref_C over which make_conditions() succeeds (the laws
// give a positive susceptibility, physical JA coefficients, a positive resistivity and sleeve
// modulus, lengths > 0): a 1 degC scan, then bisection to 0.01 degC. nullopt if the model
// cannot be computed even at T_ref. About 700 evaluations of the laws (milliseconds).
std::optional<TemperatureRange> computable_range(const Model& m, const Freeze& freeze = {});
// "[-270.15, 287.63] degC" or "[-270.15, 380) degC (below T_c)".
std::string range_text(const TemperatureRange& r);

// [validity] validated_min_C .. validated_max_C of the model (default: 20-150 degC, the range
// of the paper's measurements).
TemperatureRange validated_range(const Model& m);
// A warning when temperature_C lies outside the validated range ("temperature 250 degC: outside
// the range where <model> was validated, [20, 150] degC (validity.validated_min_C/max_C); the
// results are an extrapolation"), else nullopt.
std::optional<std::string> temperature_warning(const Model& m, double temperature_C);

}  // namespace gmasim
