// The parameter table (gmasim/model/parameters.hpp): the one place that says which numbers and
// options a model file holds, their units, rules and meaning, and where each lands in
// Model. To add a parameter: a row here, its line in the model files, and the Model field.
#include "gmasim/model/parameters.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/model/model.hpp"
#include "model/parameter_rows.hpp"

namespace gmasim {
namespace {

// ---- where a value lands: a reference into the Model for instance i ---------------------
template <auto P>
double& in_model(Model& m, std::size_t) {
  return m.*P;
}
template <auto P>
double& in_material(Model& m, std::size_t) {
  return m.material.*P;
}
template <auto P>
double& in_rod(Model& m, std::size_t i) {
  return m.rods[i].*P;
}
template <auto P>
double& in_element(Model& m, std::size_t i) {
  return m.elements[i].*P;
}
template <auto P>
double& in_sensor_mount(Model& m, std::size_t) {
  return m.sensor_mount.*P;
}
template <auto P>
double& in_sleeve(Model& m, std::size_t i) {
  return m.sleeves[i].*P;
}
template <std::size_t K>
double& in_sleeve_length(Model& m, std::size_t i) {
  return m.sleeves[i].lengths_m[K];
}
template <std::size_t K>
double& in_sleeve_area(Model& m, std::size_t i) {
  return m.sleeves[i].areas_m2[K];
}
template <auto P>
double& in_branch(Model& m, std::size_t i) {
  return m.circuit.branches[i].*P;
}
template <auto P>
double& in_expansion(Model& m, std::size_t) {
  return m.thermal_expansion.*P;
}
template <auto P>
double& in_network(Model& m, std::size_t) {
  return m.thermal_network.*P;
}
template <auto P>
double& in_validity(Model& m, std::size_t) {
  return m.validity.*P;
}

#define LAND GMASIM_LAND

using G = Group;
using R = Rule;
using Cross = CrossRule;

constexpr GroupDef kGroups[] = {
    {G::Reference, "reference", TableRule::Required, "The reference temperature of the laws"},
    {G::Material, "material", TableRule::Required, "Terfenol-D, shared by the rods"},
    {G::Preload, "preload", TableRule::Required, "The disk-spring preload through the rod stack"},
    {G::Magnet, "magnet", TableRule::Defaulted,
     "Temperature coefficients of the permanent magnet's MMF, eq. (1)"},
    {G::Rod, "<rod>", TableRule::Required, "One Terfenol-D rod of stack.rods"},
    {G::Reluctance, "circuit.reluctances_per_H", TableRule::Required,
     "Named fixed reluctances; a branch's `series` sums them"},
    {G::ReluctanceGeometry, "circuit.reluctance_geometry.<name>", TableRule::Required,
     "A fixed reluctance of [circuit.reluctances_per_H] given by its geometry: the reluctance "
     "circuit.reluctances_per_H.<name> = l / (mu0 mu_r A) is derived from it "
     "(gmasim/model/derived.hpp)"},
    {G::Branch, "circuit.branches.<name>", TableRule::KeysOptional,
     "The sources of a branch of [[circuit.branches]] (absent: 0)"},
    {G::Element, "mechanics.elements.<name>", TableRule::Required,
     "A member of a load chain with constant mass, stiffness and damping (magnetizer, output "
     "rod, disk spring)"},
    {G::SensorMount, "mechanics.sensor_mount", TableRule::Optional,
     "The displacement sensor's probe on its bracket on the housing, shaken by the housing's "
     "recoil against the moving stack (absent: the sensor reads the stack output)"},
    {G::SleeveModulus, "mechanics.sleeve_modulus", TableRule::Defaulted,
     "The sleeves' modulus law E_t^T = E_t - dE_t/dT T, eq. (19)"},
    {G::Sleeve, "mechanics.sleeves.<name>", TableRule::Required,
     "A three-section sleeve of eq. (19) in a load chain"},
    {G::ThermalExpansion, "thermal_expansion", TableRule::Defaulted,
     "The stack's thermal expansion, eq. (21)"},
    {G::ThermalNetwork, "thermal_network", TableRule::Defaulted,
     "The lumped thermal network of self-heating (coil, rods, housing, ambient)"},
    {G::Validity, "validity", TableRule::Defaulted,
     "Where the model was validated; outside, runs are warned about (docs/model.md, "
     "\"Physical validity\")"},
};

constexpr std::string_view kNoMagnet =
    "default: no permanent-magnet temperature coefficient (or no magnet)";
constexpr std::string_view kNoMagnetizer = "default: no magnetizer in the stack";
constexpr std::string_view kNoOutputRod = "default: no output rod in the stack";
constexpr std::string_view kNoSleeve = "default: no sleeve in the stack";
constexpr std::string_view kPaperRange =
    "default: the paper's measurements, 20-150 degC (section 4)";

// The rows, by group in file order. A row's default makes the key optional (Defaulted
// tables only).
const ParamDef kParams[] = {
    // [reference]
    {G::Reference, "T_ref_C", "degC", R::AboveAbsoluteZero,
     "reference temperature: T_0 of eq. (1), (8), T_r of eq. (4), (10); Table 4 holds here",
     LAND(in_model, Model, T_ref_C)},
    // [material]
    {G::Material, "Ms_A_per_m", "A/m", R::Positive,
     "saturation magnetisation M_s at T_ref, eq. (4)", LAND(in_material, Material, Ms_A_per_m)},
    {G::Material, "lambda_s", "-", R::Positive, "saturation magnetostriction, eq. (6), (11), (13)",
     LAND(in_material, Material, lambda_s)},
    {G::Material, "sigma_lambda_Pa", "Pa", R::Positive,
     "stress scale sigma_lambda of eq. (6), (13)", LAND(in_material, Material, sigma_lambda_Pa)},
    {G::Material, "Es_Pa", "Pa", R::Positive, "Young's modulus at saturation E_s, eq. (13)",
     LAND(in_material, Material, Es_Pa)},
    {G::Material,
     "Tc_C",
     "degC",
     R::Any,
     "Curie temperature T_c, eq. (4), (10)",
     LAND(in_material, Material, Tc_C),
     std::nullopt,
     {},
     Cross{Cross::Above, "reference.T_ref_C"}},
    {G::Material, "rho0_ohm_m", "ohm m", R::Positive, "resistivity at T_0, eq. (8)",
     LAND(in_material, Material, rho0_ohm_m)},
    {G::Material, "drho_dT_ohm_m_per_K", "ohm m/K", R::Any, "resistivity slope, eq. (8)",
     LAND(in_material, Material, drho_dT_ohm_m_per_K)},
    {G::Material, "beta_per_K", "1/K", R::Any, "temperature coefficient beta of eq. (3), (13)",
     LAND(in_material, Material, beta_per_K)},
    {G::Material, "chi_m", "-", R::Positive, "initial susceptibility chi_m of eq. (3), (5), (13)",
     LAND(in_material, Material, chi_m)},
    {G::Material, "x", "-", R::Positive, "critical exponent x of M_s^T, eq. (4)",
     LAND(in_material, Material, x_exponent)},
    {G::Material, "alpha_thermal_per_K", "1/K", R::NonNegative,
     "thermal expansion coefficient of the rods, eq. (21) and l^T, A^T",
     LAND(in_material, Material, alpha_thermal_per_K)},
    {G::Material, "density_kg_per_m3", "kg/m^3", R::Positive,
     "density of the rods' material: their derived mass (gmasim/model/derived.hpp)",
     LAND(in_material, Material, density_kg_per_m3), 9250.0,
     "default: Terfenol-D, 9.2-9.25 g/cm^3 (manufacturers' data sheets)"},
    // [preload]
    {G::Preload,
     "force_N",
     "N",
     R::NonNegative,
     "preload F_pre through the rods in series; each rod's prestress is F_pre / A_i^T (its "
     "area at temperature), eq. (3), (6), (11), (13). Give this or prestress_MPa",
     LAND(in_model, Model, preload_N),
     std::nullopt,
     {},
     {},
     "prestress_MPa"},
    {G::Preload,
     "prestress_MPa",
     "MPa",
     R::NonNegative,
     "the preload as the compressive prestress of the first rod of stack.rods at T_ref; the "
     "force is derived, F_pre = prestress x A_1 (A_1 = pi (r_1^2 - r_2^2) at T_ref). Give this "
     "or force_N",
     nullptr,
     "Model::preload_N (derived: prestress x A_1)",
     std::nullopt,
     {},
     {},
     "force_N"},
    // [magnet]
    {G::Magnet, "alpha_pm1_per_K", "1/K", R::Any, "first-order coefficient of F_pm^T, eq. (1)",
     LAND(in_model, Model, alpha_pm1_per_K), 0.0, kNoMagnet},
    {G::Magnet, "alpha_pm2_per_K2", "1/K^2", R::Any, "second-order coefficient of F_pm^T, eq. (1)",
     LAND(in_model, Model, alpha_pm2_per_K2), 0.0, kNoMagnet},
    // [<rod>]
    {G::Rod, "outer_diameter_m", "m", R::Positive, "outer diameter 2 r_1, eq. (2), (7), (14)",
     LAND(in_rod, RodModel, outer_diameter_m)},
    {G::Rod,
     "inner_diameter_m",
     "m",
     R::NonNegative,
     "inner diameter 2 r_2 (0: a cylinder)",
     LAND(in_rod, RodModel, inner_diameter_m),
     std::nullopt,
     {},
     Cross{Cross::Below, "outer_diameter_m"}},
    {G::Rod, "length_m", "m", R::Positive, "length l_i, eq. (2), (17)",
     LAND(in_rod, RodModel, length_m)},
    {G::Rod, "mass_kg", "kg", R::Positive,
     "mass m_i, eq. (24); derived from the geometry when the file omits it",
     LAND(in_rod, RodModel, mass_kg), 0.0,
     "derived: material.density_kg_per_m3 x pi (r_o^2 - r_i^2) x length_m"},
    {G::Rod, "k_f", "-", R::Positive,
     "flux-leakage factor k_f of eq. (7) (the printed reading; the consistent reading uses "
     "joint_gap_m)",
     LAND(in_rod, RodModel, k_f)},
    {G::Rod, "k_j", "-", R::Positive, "eddy-current factor k_j of eq. (7)",
     LAND(in_rod, RodModel, k_j)},
    {G::Rod, "joint_gap_m", "m", R::NonNegative,
     "consistent reading: the equivalent air gap of the rod's joints (between its short rods and "
     "against the magnetizers), a lossless series reluctance g / (mu0 A) in its branch",
     LAND(in_rod, RodModel, joint_gap_m), 0.0, "default: no joints (one solid rod)"},
    {G::Rod, "joint_modulus_Pa", "Pa", R::Positive,
     "Young's modulus of the joints' bond line: their compliance joint_gap_m / (E_j A) in series "
     "with the rod when options.joint_mechanics = bonded (unused when rigid)",
     LAND(in_rod, RodModel, joint_modulus_Pa), 3.0e9,
     "default: a cured structural epoxy, ~3 GPa at room temperature (da Silva and Adams, J. "
     "Adhesion Sci. Technol. 19 (2005) 109; Anasiewicz et al., Materials 15 (2022) 8060)"},
    {G::Rod, "damping_N_s_per_m", "N s/m", R::Positive, "damping c_i, eq. (25)",
     LAND(in_rod, RodModel, damping_N_s_per_m)},
    // [circuit.reluctances_per_H]
    {G::Reluctance, "*", "1/H", R::Positive,
     "a fixed reluctance of Table 1 (any name); summed over a branch's series, eq. (23)", nullptr,
     "CircuitBranch::fixed_reluctance_per_H (the sum over `series`)"},
    // [circuit.reluctance_geometry.<name>]: inputs of a derived reluctance (not landed)
    {G::ReluctanceGeometry, "length_m", "m", R::Positive,
     "the flux path's length l through the part", nullptr,
     "derives circuit.reluctances_per_H.<name> = l / (mu0 mu_r A)"},
    {G::ReluctanceGeometry, "area_m2", "m^2", R::Positive, "the flux path's cross-section A",
     nullptr, "derives circuit.reluctances_per_H.<name> = l / (mu0 mu_r A)"},
    {G::ReluctanceGeometry, "relative_permeability", "-", R::Positive,
     "the part's relative permeability mu_r (1 for air, epoxy and the magnets' recoil ~1.05; "
     "a steel's at its working flux)",
     nullptr, "derives circuit.reluctances_per_H.<name> = l / (mu0 mu_r A)"},
    // [[circuit.branches]]
    {G::Branch, "coil_turns", "turns", R::NonNegative,
     "turns N of the coil in the branch: MMF N I, eq. (22)-(23)",
     LAND(in_branch, CircuitBranch, coil_turns)},
    {G::Branch, "pm_mmf_At", "A-turns", R::Any,
     "permanent-magnet MMF F_pm at T_0 in the branch, eq. (1), (22)",
     LAND(in_branch, CircuitBranch, pm_mmf_At)},
    // [mechanics.elements.<name>]
    {G::Element, "mass_kg", "kg", R::NonNegative, "mass, summed into m_lr of eq. (27)",
     LAND(in_element, ChainElementModel, mass_kg)},
    {G::Element, "stiffness_N_per_m", "N/m", R::Positive, "stiffness, in series in eq. (18)",
     LAND(in_element, ChainElementModel, stiffness_N_per_m)},
    {G::Element, "damping_N_s_per_m", "N s/m", R::Positive, "damping, in series in eq. (28)",
     LAND(in_element, ChainElementModel, damping_N_s_per_m)},
    // [mechanics.sensor_mount]
    {G::SensorMount, "mass_kg", "kg", R::Positive, "mass of the sensor probe and its bracket",
     LAND(in_sensor_mount, SensorMountModel, mass_kg)},
    {G::SensorMount, "stiffness_N_per_m", "N/m", R::Positive, "stiffness of the bracket",
     LAND(in_sensor_mount, SensorMountModel, stiffness_N_per_m)},
    {G::SensorMount, "damping_N_s_per_m", "N s/m", R::NonNegative, "damping of the bracket",
     LAND(in_sensor_mount, SensorMountModel, damping_N_s_per_m)},
    {G::SensorMount, "actuator_mass_kg", "kg", R::Positive,
     "mass of the whole actuator, which recoils against its moving stack (section 1: 787 g)",
     LAND(in_sensor_mount, SensorMountModel, actuator_mass_kg)},
    // [mechanics.sleeve_modulus]
    {G::SleeveModulus, "Et_Pa", "Pa", R::Positive, "E_t, the modulus law's 0 degC value, eq. (19)",
     LAND(in_model, Model, Et_Pa), 200e9, "default: steel; used only by [mechanics.sleeves]"},
    {G::SleeveModulus, "dEt_dT_Pa_per_C", "Pa/degC", R::Any, "its slope dE_t/dT, eq. (19)",
     LAND(in_model, Model, dEt_dT_Pa_per_C), 0.0, "default: temperature-independent"},
    // [mechanics.sleeves.<name>]
    {G::Sleeve, "mass_kg", "kg", R::Positive, "mass m_t, eq. (27)",
     LAND(in_sleeve, SleeveModel, mass_kg)},
    {G::Sleeve, "damping_N_s_per_m", "N s/m", R::Positive, "damping c_t, eq. (28)",
     LAND(in_sleeve, SleeveModel, damping_N_s_per_m)},
    {G::Sleeve, "alpha_thermal_per_K", "1/K", R::NonNegative,
     "thermal expansion coefficient of its l^T, A^T",
     LAND(in_sleeve, SleeveModel, alpha_thermal_per_K)},
    {G::Sleeve, "l1_m", "m", R::Positive, "length of section 1, eq. (19)", &in_sleeve_length<0>,
     "SleeveModel::lengths_m[0]"},
    {G::Sleeve, "l2_m", "m", R::Positive, "length of section 2, eq. (19)", &in_sleeve_length<1>,
     "SleeveModel::lengths_m[1]"},
    {G::Sleeve, "l3_m", "m", R::Positive, "length of section 3, eq. (19)", &in_sleeve_length<2>,
     "SleeveModel::lengths_m[2]"},
    {G::Sleeve, "A1_m2", "m^2", R::Positive, "area of section 1, eq. (19)", &in_sleeve_area<0>,
     "SleeveModel::areas_m2[0]"},
    {G::Sleeve, "A2_m2", "m^2", R::Positive, "area of section 2, eq. (19)", &in_sleeve_area<1>,
     "SleeveModel::areas_m2[1]"},
    {G::Sleeve, "A3_m2", "m^2", R::Positive, "area of section 3, eq. (19)", &in_sleeve_area<2>,
     "SleeveModel::areas_m2[2]"},
    // [thermal_expansion]
    {G::ThermalExpansion, "rod_length_m", "m", R::NonNegative,
     "expanding length of the rods, eq. (21) (0: the longest rod)",
     LAND(in_expansion, ThermalExpansionModel, rod_length_m), 0.0,
     "default: 0 = the longest rod of stack.rods"},
    {G::ThermalExpansion, "magnetizer_length_m", "m", R::NonNegative,
     "length of the magnetizers, eq. (21)",
     LAND(in_expansion, ThermalExpansionModel, magnetizer_length_m), 0.0, kNoMagnetizer},
    {G::ThermalExpansion, "magnetizer_alpha_per_K", "1/K", R::NonNegative,
     "their expansion coefficient, eq. (21)",
     LAND(in_expansion, ThermalExpansionModel, magnetizer_alpha_per_K), 0.0, kNoMagnetizer},
    {G::ThermalExpansion, "output_rod_length_m", "m", R::NonNegative,
     "length of the output rod, eq. (21)",
     LAND(in_expansion, ThermalExpansionModel, output_rod_length_m), 0.0, kNoOutputRod},
    {G::ThermalExpansion, "output_rod_alpha_per_K", "1/K", R::NonNegative,
     "its expansion coefficient, eq. (21)",
     LAND(in_expansion, ThermalExpansionModel, output_rod_alpha_per_K), 0.0, kNoOutputRod},
    {G::ThermalExpansion, "sleeve_length_m", "m", R::NonNegative,
     "length of the sleeve, eq. (21) (subtracted)",
     LAND(in_expansion, ThermalExpansionModel, sleeve_length_m), 0.0, kNoSleeve},
    {G::ThermalExpansion, "sleeve_alpha_per_K", "1/K", R::NonNegative,
     "its expansion coefficient, eq. (21)",
     LAND(in_expansion, ThermalExpansionModel, sleeve_alpha_per_K), 0.0, kNoSleeve},
    // [thermal_network]
    {G::ThermalNetwork, "coil_resistance_ohm", "ohm", R::Positive,
     "coil resistance at T_ref: copper loss I^2 R(T)",
     LAND(in_network, ThermalNetworkModel, coil_resistance_ohm), 1.5,
     "default: estimate for the MDMA coil (720 turns of ~0.8 mm copper), at reference.T_ref_C"},
    {G::ThermalNetwork, "coil_wire_diameter_m", "m", R::NonNegative,
     "the winding's wire diameter (bare copper): with coil_mean_turn_length_m, the coil "
     "resistance is derived from the turns (gmasim/model/derived.hpp)",
     LAND(in_network, ThermalNetworkModel, coil_wire_diameter_m), 0.0,
     "default: not given (coil_resistance_ohm is then an input)"},
    {G::ThermalNetwork, "coil_mean_turn_length_m", "m", R::NonNegative,
     "the winding's mean turn length (pi x the mean winding diameter)",
     LAND(in_network, ThermalNetworkModel, coil_mean_turn_length_m), 0.0,
     "default: not given (coil_resistance_ohm is then an input)"},
    {G::ThermalNetwork, "coil_resistivity_ohm_m", "ohm m", R::Positive,
     "resistivity of the winding at T_ref (the derived resistance)",
     LAND(in_network, ThermalNetworkModel, coil_resistivity_ohm_m), 1.7241e-8,
     "default: annealed copper at 20 degC, 1.7241e-8 ohm m (IEC 60028)"},
    {G::ThermalNetwork, "coil_alpha_per_K", "1/K", R::NonNegative,
     "temperature coefficient of the coil resistance, R(T) = R (1 + alpha (T - T_ref))",
     LAND(in_network, ThermalNetworkModel, coil_alpha_per_K), 3.93e-3,
     "default: copper, handbook value"},
    {G::ThermalNetwork, "coil_heat_capacity_J_per_K", "J/K", R::Positive,
     "heat capacity of the coil node; derived from the winding's copper when it is given "
     "(gmasim/model/derived.hpp)",
     LAND(in_network, ThermalNetworkModel, coil_C_J_per_K), 80.0,
     "default: estimate, ~0.2 kg of copper x 385 J/(kg K)"},
    {G::ThermalNetwork, "coil_density_kg_per_m3", "kg/m^3", R::Positive,
     "density of the winding's conductor (the derived coil heat capacity)",
     LAND(in_network, ThermalNetworkModel, coil_density_kg_per_m3), 8890.0,
     "default: annealed copper, 8890 kg/m^3 (IEC 60028)"},
    {G::ThermalNetwork, "coil_specific_heat_J_per_kg_K", "J/(kg K)", R::Positive,
     "specific heat of the winding's conductor (the derived coil heat capacity)",
     LAND(in_network, ThermalNetworkModel, coil_specific_heat_J_per_kg_K), 385.0,
     "default: copper at 20 degC, 385 J/(kg K) (handbook value)"},
    {G::ThermalNetwork, "rod_specific_heat_J_per_kg_K", "J/(kg K)", R::Positive,
     "specific heat of Terfenol-D; times the rods' mass, the rods node's heat capacity",
     LAND(in_network, ThermalNetworkModel, rod_specific_heat_J_per_kg_K), 350.0,
     "default: Terfenol-D, ~0.35 kJ/(kg K) (manufacturer data)"},
    {G::ThermalNetwork, "housing_heat_capacity_J_per_K", "J/K", R::Positive,
     "heat capacity of the housing node", LAND(in_network, ThermalNetworkModel, housing_C_J_per_K),
     450.0, "default: estimate, ~1 kg of steel x 460 J/(kg K)"},
    {G::ThermalNetwork, "coil_to_rods_W_per_K", "W/K", R::Positive,
     "thermal conductance coil - rods", LAND(in_network, ThermalNetworkModel, G_coil_rods_W_per_K),
     0.5, "default: estimate, conduction across the coil former and air gap"},
    {G::ThermalNetwork, "coil_to_housing_W_per_K", "W/K", R::Positive,
     "thermal conductance coil - housing",
     LAND(in_network, ThermalNetworkModel, G_coil_housing_W_per_K), 1.0,
     "default: estimate, coil potted to the housing"},
    {G::ThermalNetwork, "rods_to_housing_W_per_K", "W/K", R::Positive,
     "thermal conductance rods - housing",
     LAND(in_network, ThermalNetworkModel, G_rods_housing_W_per_K), 0.5,
     "default: estimate, conduction through the magnetizers and end caps"},
    {G::ThermalNetwork, "housing_to_ambient_W_per_K", "W/K", R::Positive,
     "thermal conductance housing - ambient",
     LAND(in_network, ThermalNetworkModel, G_housing_ambient_W_per_K), 0.4,
     "default: estimate, natural convection ~10 W/(m^2 K) over ~0.04 m^2"},
    // [validity]
    {G::Validity, "validated_min_C", "degC", R::AboveAbsoluteZero,
     "lowest temperature the model was validated at",
     LAND(in_validity, ValidityModel, validated_min_C), 20.0, kPaperRange},
    {G::Validity, "validated_max_C", "degC", R::AboveAbsoluteZero,
     "highest temperature the model was validated at",
     LAND(in_validity, ValidityModel, validated_max_C), 150.0, kPaperRange,
     Cross{Cross::Above, "validated_min_C"}},
};

#undef LAND

}  // namespace

std::string_view rule_text(Rule r) {
  switch (r) {
    case Rule::Any:
      return "any";
    case Rule::Positive:
      return "> 0";
    case Rule::NonNegative:
      return ">= 0";
    case Rule::UnitInterval:
      return "[0, 1)";
    case Rule::AboveAbsoluteZero:
      return "> -273.15 degC";
  }
  return "?";
}

std::string row_rule_text(const ParamDef& row) {
  std::string rule(rule_text(row.rule));
  if (row.cross.kind != CrossRule::None)
    rule += fmt::format(", {} {}", row.cross.kind == CrossRule::Below ? "<" : ">", row.cross.other);
  return rule;
}

bool rule_holds(Rule r, double v) {
  switch (r) {
    case Rule::Any:
      return true;
    case Rule::Positive:
      return v > 0.0;
    case Rule::NonNegative:
      return v >= 0.0;
    case Rule::UnitInterval:
      return v >= 0.0 && v < 1.0;
    case Rule::AboveAbsoluteZero:
      return v > -273.15;
  }
  return false;
}

std::string rule_message(Rule r) {
  switch (r) {
    case Rule::UnitInterval:
      return "must be in [0, 1)";
    case Rule::AboveAbsoluteZero:
      return "must be > -273.15 degC (absolute zero)";
    default:
      return fmt::format("must be {}", rule_text(r));
  }
}

std::optional<std::string> number_problem(double v) {
  if (std::isnan(v)) return "NaN is not allowed: every number must be finite";
  if (std::isinf(v)) return "Inf is not allowed: every number must be finite";
  if (v != 0.0 && !(std::fabs(v) >= kMinMagnitude && std::fabs(v) <= kMaxMagnitude))
    return fmt::format(
        "outside the range of any physical value of the model ({:g} <= |v| <= {:g}, or 0)",
        kMinMagnitude, kMaxMagnitude);
  return std::nullopt;
}

// The magnetisation laws' groups and rows (src/model/magnetisation/) follow the rod's.
std::span<const GroupDef> parameter_groups() {
  static const std::vector<GroupDef> groups = model_detail::with_law_entries(
      std::span<const GroupDef>(kGroups), [](const GroupDef& g) { return g.group; },
      [](auto law) { return law.group; });
  return groups;
}
std::span<const ParamDef> parameter_table() {
  static const std::vector<ParamDef> rows = model_detail::with_law_entries(
      std::span<const ParamDef>(kParams), [](const ParamDef& r) { return r.group; },
      [](auto law) { return law.rows; });
  return rows;
}
// option_table, the options' words: src/model/option_table.cpp.

const GroupDef& group_def(Group g) {
  for (const auto& d : parameter_groups())
    if (d.group == g) return d;
  throw std::logic_error("group_def: a group without a row");
}

// find_param_def: src/model/param_lookup.cpp.

const OptionDef* find_option_def(std::string_view key) {
  if (key.starts_with("options.")) key.remove_prefix(8);
  for (const auto& o : option_table())
    if (o.key == key) return &o;
  return nullptr;
}

std::string_view option_word(const OptionDef& def, const Options& o) {
  const int v = def.reads(o);
  for (const auto& c : def.choices)
    if (c.value == v) return c.word;
  return "?";
}

std::optional<std::string> set_option_word(const OptionDef& def, Options& o,
                                           std::string_view word) {
  for (const auto& c : def.choices) {
    if (c.word == word) {
      def.lands(o, c.value);
      return std::nullopt;
    }
  }
  std::string words;
  for (const auto& c : def.choices) words += (words.empty() ? "" : ", ") + std::string(c.word);
  return fmt::format("options.{} = \"{}\": must be one of: {}", def.key, word, words);
}

std::optional<OptionProblem> check_options(const Options& o) {
  // One reference temperature per reading (issue 7): a^T proportional to T vanishes at 0 K,
  // so Table 4's a0 can only be the T_ref value, and then k, alpha and c must be too.
  if (o.shape_law == ShapeLaw::MeanField && o.eq10_scale != Eq10Scale::RoomReferenced) {
    const std::string sc(option_word(*find_option_def("eq10_temperature_scale"), o));
    return OptionProblem{
        "options.eq10_shape_law",
        fmt::format("options.eq10_shape_law = 'mean_field' with eq10_temperature_scale = "
                    "'{}': mixes reference temperatures (a^T = a0 T/T_ref takes Table 4 at "
                    "T_ref, '{}' takes k0, alpha0, c0 at {}); use eq10_temperature_scale = "
                    "'room_referenced' (docs/model.md)",
                    sc, sc, sc == "kelvin" ? "0 K" : "0 degC")};
  }
  return std::nullopt;
}

std::string parameters_markdown() {
  std::string md =
      "# Model parameters\n\n"
      "Generated by `gmasim model params --markdown` from the parameter table "
      "(src/model/parameters.cpp); do not edit. Every number of a model file, its unit, "
      "rule, meaning and where `compile()` puts it in `Model`. Besides its rule, every number "
      "must be finite and, unless 0, between " +
      fmt::format("{:g} and {:g}", kMinMagnitude, kMaxMagnitude) + " in magnitude.\n";
  for (const auto& g : parameter_groups()) {
    const char* presence = g.table == TableRule::Required    ? "required"
                           : g.table == TableRule::Optional  ? "optional (all keys, or none)"
                           : g.table == TableRule::Defaulted ? "optional, every key defaulted"
                                                             : "optional keys (absent: 0)";
    md += fmt::format("\n## [{}]\n\n{}; {}.\n\n", g.path, g.doc, presence);
    md += "| key | unit | rule | meaning | default | lands in |\n|---|---|---|---|---|---|\n";
    for (const auto& p : parameter_table()) {
      if (p.group != g.group) continue;
      md += fmt::format("| `{}` | {} | {} | {} | {} | `{}` |\n", p.key, p.unit, row_rule_text(p),
                        p.doc, p.default_value ? fmt::format("{:g}", *p.default_value) : "",
                        p.lands_in);
    }
  }
  md +=
      "\n## [options]\n\nEvery option is required: a model file states its reading (an option "
      "with a default may be omitted).\n\n";
  md += "| key | values | meaning | lands in |\n|---|---|---|---|\n";
  for (const auto& o : option_table()) {
    std::string values;
    for (const auto& c : o.choices)
      values += fmt::format("{}`{}`{}", values.empty() ? "" : "; ", c.word,
                            o.boolean ? "" : fmt::format(": {}", c.doc));
    const std::string doc = o.default_word.empty()
                                ? std::string(o.doc)
                                : fmt::format("{} (default: `{}`)", o.doc, o.default_word);
    md += fmt::format("| `{}` | {} | {} | `{}` |\n", o.key, values, doc, o.lands_in);
  }
  return md;
}

}  // namespace gmasim
