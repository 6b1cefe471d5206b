// ModelSpec (plain data read from TOML) -> Model (immutable, compiled) -> Conditions
// (every temperature-dependent constant at one temperature) -> State + step().
#pragma once

#include <array>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "gmasim/model/circuit.hpp"
#include "gmasim/model/energy.hpp"
#include "gmasim/model/parameters.hpp"
#include "gmasim/physics/jiles_atherton.hpp"
#include "gmasim/physics/magnetostriction.hpp"
#include "gmasim/physics/preisach.hpp"

namespace gmasim {

// ---------------------------------------------------------------------------------------
// Options: the readings READING-NOTES leaves open (docs/model.md).
// ---------------------------------------------------------------------------------------
enum class StressSign { CompressionNegative, CompressionPositive };
enum class Eq10Scale { RoomReferenced, Kelvin, Celsius };
enum class ShapeLaw { Printed, MeanField };
// How a rod's flux, field and magnetisation relate (docs/model.md, "Magnetic state").
//   Printed:    eq. (2), (3), (7) as printed: the circuit passes phi = U mu_G A / l with mu_G of
//               eq. (3), and the material sees H_c = phi / (k_f mu_G A). phi / A is not
//               mu0 (H + M) of the JA state (it reaches 3.6 T in rod 2).
//   Consistent: the rod branch carries the flux of its own material state, phi = A mu0 (H + M),
//               over the magnetic length k_f l (U = k_f l H_c, so H_c is eq. 7's first line);
//               the eddy field of eq. (7) is H_c - H = kappa dB/dt; eq. (3)'s stress terms enter
//               the JA effective field as a magnetoelastic coupling. B never exceeds
//               mu0 (H + M_s^T).
enum class MagneticState { Printed, Consistent };
// The saturation magnetisation that normalises M in eq. (11), lambda = f lambda_s (M/M_s)^2:
//   Temperature: M_s^T of eq. (4), as printed (the strain at saturation is the same at any T);
//   Reference:   M_s at T_r, i.e. lambda_s^T = lambda_s (M_s^T/M_s)^2: the strain is a function
//                of the magnetisation alone (classical magnetoelastic scaling, docs/model.md).
enum class Eq11Saturation { Temperature, Reference };
// The eddy-current coefficient kappa of eq. (7), H_c - H = kappa dB/dt (docs/model.md, "The
// eddy law"):
//   Table4:    kappa = (r1^2 - r2^2)/(4 k_j rho) with Table 4's factor k_j, as printed;
//   Classical: the quasi-static field of azimuthal eddy currents in a long tube of radii
//              r2 < r1, averaged over its section (r1^2/(8 rho) for a solid rod); k_j unused.
enum class EddyLaw { Table4, Classical };
// What moves the base of the sensor mount's bracket (docs/model.md, "The sensor mount"):
//   Recoil: the housing's recoil q = p / M; the probe sits on a bracket of the shell and the
//           sensor reads y_stack + (z - q): the bracket's resonance with an antiresonance above it;
//   Output: the actuator's output q = y_stack; the probe's tip rides on the output through the
//           bracket's spring and the sensor reads the probe, y = z: base excitation, the
//           resonance and no antiresonance (issue 37's mount reading).
enum class SensorMountBase { Recoil, Output };
// The mechanics of the rods' joints (docs/model.md, "The joints"), each of thickness joint_gap_m:
//   Rigid:  the joints carry no compliance (eq. 15-18 as printed: the gap is magnetic only);
//   Bonded: each joint is a bond line of modulus joint_modulus_Pa, a compliance
//           g / (E_j A) in series with the rod's own l / (E A) (eq. 17): the rod's free stroke
//           lambda l holds, its stiffness and blocked force fall by 1 / (1 + k_rod g / (E_j A)).
enum class JointMechanics { Rigid, Bonded };

// Parsed once, by the loader or ModelSpec::set_options, from the words of the option table
// (gmasim/model/parameters.hpp). The defaults are the built-in model's readings (a test holds them
// to models/mdma.toml): a ModelSpec built in code has them unless it sets others; a model file
// must state every option.
struct Options {
  StressSign stress_sign = StressSign::CompressionNegative;
  Eq10Scale eq10_scale = Eq10Scale::RoomReferenced;
  ShapeLaw shape_law = ShapeLaw::MeanField;
  MagneticState magnetic_state = MagneticState::Consistent;
  Eq11Saturation eq11_saturation = Eq11Saturation::Reference;
  bool thermal_expansion_in_output = false;
  bool geometry_thermal_expansion = true;
  MagnetisationLaw magnetisation_law = MagnetisationLaw::JilesAtherton;
  EddyLaw eddy_law = EddyLaw::Table4;
  SensorMountBase sensor_mount_base = SensorMountBase::Recoil;
  JointMechanics joint_mechanics = JointMechanics::Rigid;
  bool operator==(const Options&) const = default;
};

// ---------------------------------------------------------------------------------------
// ModelSpec: what the TOML file says, validated field by field, with provenance.
// ---------------------------------------------------------------------------------------
// A number of the model file. Its unit, rule and meaning are its row's in the parameter table
// (ModelSpec::def_of, unit_of).
struct ParamValue {
  double value = 0.0;
  std::string provenance;  // the trailing comment of the TOML line ("Table 4", ...)
  long line = 0;           // source line in the model file (0: a default of its row)
  bool assigned = false;   // set after loading (ModelSpec::set, --set): never re-derived
};

struct SpecBranch {
  std::string name, from, to;
  std::vector<std::string> series;  // names in [circuit.reluctances], summed
  std::string rod;                  // or the rod whose eq. (2) reluctance this is
  long line = 0;
};

struct ModelSpec {
  std::string source;  // file path, or "models/mdma.toml (built-in)"
  std::string text;    // the TOML text it was parsed from (model_toml() edits it)
  // Every numeric parameter by its dotted TOML name ("rod1.ja.k0_A_per_m").
  std::map<std::string, ParamValue> params;
  Options options;  // [options], parsed (gmasim/model/parameters.hpp, option_table())
  std::map<std::string, std::string> meta;  // [meta] texts by dotted name ("meta.name")
  // Source lines of the options, the meta texts, structure keys and optional tables'
  // headers, by dotted name ("options.magnetic_state", "stack.rods", "[thermal_network]").
  std::map<std::string, long> option_lines;
  std::vector<std::string> rods;  // stack.rods, in order
  std::string reference_node;
  std::vector<std::string> nodes;  // circuit.nodes: the non-reference nodes
  long nodes_line = 0;
  std::vector<SpecBranch> branches;
  std::vector<std::string> flux_sensor_branches;           // sensor.flux_branches
  std::vector<std::string> element_names;                  // mechanics.elements.*
  std::vector<std::string> sleeve_names;                   // mechanics.sleeves.*
  std::vector<std::string> reluctance_geometry_names;      // circuit.reluctance_geometry.*
  std::map<std::string, std::vector<std::string>> chains;  // rod -> load chain (eq. 18/27/28)
  // [calibration] fitted_claims: the claims this model was fitted to (gmasim identify writes
  // them); gmasim reproduce counts the other claims as predictions.
  std::vector<std::string> fitted_claims;

  double get(const std::string& dotted) const;  // throws InputError if unknown
  // Sets a number after checking it against its row's rule and the cross-field rules that
  // involve it; throws InputError (and leaves the spec unchanged) if unknown or refused.
  void set(const std::string& dotted, double value);
  // Sets options ("options.magnetic_state" or "magnetic_state") from their words, all at
  // once: the rules between options (gmasim/model/parameters.hpp, check_options) apply to the
  // result, whatever the order. Throws InputError naming the allowed words or the rule broken,
  // and leaves the options unchanged.
  void set_options(const std::vector<std::pair<std::string, std::string>>& name_word);
  void set_option(const std::string& name, const std::string& word) { set_options({{name, word}}); }
  // The row of a stored number (nullptr if none fits) and its unit ("-" if none).
  const ParamDef* def_of(const std::string& key) const;
  std::string unit_of(const std::string& key) const;
  long line_of(const std::string& dotted) const;
  // The full key a dotted name resolves to: the name itself, or the unique dimensionless
  // "<name>_<rest>" ("material.lambda" -> "material.lambda_s"); throws InputError if unknown,
  // ambiguous, or a dimensional key without its unit suffix ("rod1.ja.k0": write
  // "rod1.ja.k0_A_per_m"; issue 19, item 9), as get() and set() do.
  std::string key_of(const std::string& dotted) const;
};

// The preload of a spec (docs/model.md, "Preload"): a file gives preload.force_N or
// preload.prestress_MPa, the compressive stress of the first rod of stack.rods at T_ref.
// preload_area_m2: that rod's cross-section pi (r_1^2 - r_2^2) at T_ref [m^2].
double preload_area_m2(const ModelSpec& spec);
// The preload force [N]: force_N, or prestress_MPa x 1e6 x preload_area_m2.
double preload_force_N(const ModelSpec& spec);
// "preload.force_N" or "preload.prestress_MPa": the key the spec holds.
std::string preload_key(const ModelSpec& spec);

// One switch per temperature law: a frozen law is evaluated at the reference
// temperature T_r (20 degC) whatever the operating temperature. Used by ablation.
struct Freeze {
  bool pm_mmf = false;          // eq. (1)
  bool permeability = false;    // eq. (3)-(4) inside mu_G (and the eddy tau through mu_G)
  bool resistivity = false;     // eq. (8)
  bool magnetisation = false;   // eq. (10) JA coefficients, M_s^T of eq. (9) and (11)
  bool modulus = false;         // eq. (13) E_G (its M_s^T and beta dT terms)
  bool sleeve_modulus = false;  // eq. (19) E_t^T
  bool geometry = false;        // thermal expansion of lengths and areas
};

// The Freeze switches by name, one row each (MuJoCo's mjDISABLESTRING style): the one name
// set of the CLI (`simulate --freeze`, `ablate`), the Python module (`freeze=[...]`), the
// ablation report and metrics.json ("frozen"), in the order of Fig. 20.
struct FreezeSwitch {
  const char* name;         // e.g. "mu_G"
  bool Freeze::*flag;       // the switch it sets
  const char* description;  // what it freezes (the ablation report's "freezes" column)
};
inline constexpr FreezeSwitch kFreezeSwitches[] = {
    {"mu_G", &Freeze::permeability,
     "permeability of the rods, eq. (3)-(4) (and the eddy time constant through mu)"},
    {"rho_G", &Freeze::resistivity, "resistivity of the rods, eq. (8)"},
    {"M", &Freeze::magnetisation,
     "magnetisation process: JA coefficients of eq. (10), M_s^T in eq. (9) and (11)"},
    {"E_G", &Freeze::modulus, "Delta-E modulus of the rods, eq. (13)"},
    {"E_t", &Freeze::sleeve_modulus, "sleeve modulus, eq. (19)"},
    {"F_pm", &Freeze::pm_mmf, "permanent-magnet MMF, eq. (1)"},
    {"geometry", &Freeze::geometry, "thermal expansion of lengths and areas (eq. 2, 7, 17, 19)"},
};
// The switches named in `names` set (kFreezeSwitches names). Throws InputError "unknown law
// 'x' to freeze; known: mu_G, rho_G, ..." for any other name.
Freeze parse_freeze(const std::vector<std::string>& names);
// The names of the switches `f` sets, in table order.
std::vector<std::string> frozen_names(const Freeze& f);
// "mu_G, rho_G, M, E_G, E_t, F_pm, geometry": for help texts and messages.
std::string freeze_name_list();

// ---------------------------------------------------------------------------------------
// Model: compiled, immutable.
// ---------------------------------------------------------------------------------------
struct JaReference {
  double a0_A_per_m, alpha0, c0, k0_A_per_m, beta1, beta2, beta3;
};

// The Preisach law's constants at T_ref ([<rod>.preisach]; docs/model.md, "The Preisach law").
struct PreisachReference {
  double Hc0_A_per_m = 0;  // median coercive field of the hysterons at T_ref
  double sigma_c = 0;      // log-normal width of the coercive fields
  double Hu0_A_per_m = 0;  // standard deviation of the interaction fields at T_ref
  double n_c = 0;          // coercivity law H_c^T = H_c0 (M_s^T / M_s)^n_c
  double c0 = 0;           // reversible fraction
  double a0_A_per_m = 0;   // reversible Langevin shape at T_ref (a^T = a0 T/T_ref)
  double alpha0 = 0;       // mean-field coupling
};

struct RodModel {
  std::string name;
  double length_m, outer_diameter_m, inner_diameter_m, mass_kg;  // at T_ref
  double k_f, k_j;               // eq. (7) flux-leakage and eddy-current factors
  double joint_gap_m;            // consistent reading: equivalent air gap of the rod's joints
  double joint_modulus_Pa;       // their bond's modulus (options.joint_mechanics = bonded)
  double damping_N_s_per_m;      // c_i of eq. (25)
  JaReference ja;                // the Jiles-Atherton law's constants (options.magnetisation_law)
  PreisachReference preisach{};  // the Preisach law's
};

struct Material {  // Terfenol-D, shared by the rods
  double Ms_A_per_m, lambda_s, sigma_lambda_Pa, Es_Pa, Tc_C, rho0_ohm_m, drho_dT_ohm_m_per_K;
  double beta_per_K, chi_m, x_exponent, alpha_thermal_per_K;
  double density_kg_per_m3;  // the rods' mass (derived quantities, gmasim/model/derived.hpp)
};

struct ChainElementModel {  // a magnetizer, output rod or disk spring: constant m, k, c
  std::string name;
  double mass_kg, stiffness_N_per_m, damping_N_s_per_m;
};

struct SleeveModel {  // eq. (19)
  std::string name;
  double mass_kg, damping_N_s_per_m;
  std::array<double, 3> lengths_m, areas_m2;
  double alpha_thermal_per_K;
};

// Optional sensor mount (`[mechanics.sensor_mount]`; docs/model.md, "The sensor mount"): the
// capacitive probe on its bracket on the housing (section 4.5: the sensor, on the outer shell,
// "has certain vibrations"). The housing of mass M (the whole actuator, section 1) recoils
// against the stack's momentum p = sum_i (m_i/2 + m_lr,i) x_i (eq. 27's masses), x_h = -p/M;
// the probe's deflection u on the bracket obeys m u'' + c u' + k u = -m x_h'', and the sensor
// reads y_stack - u. Temperature-independent; the recoil's back-action on the stack is not
// modelled (the stack's motion is relative to the housing, as in eq. 15).
struct SensorMountModel {
  bool enabled = false;
  double mass_kg = 0, stiffness_N_per_m = 0, damping_N_s_per_m = 0;
  double actuator_mass_kg = 0;
};

// Lumped thermal network of self-heating (optional table [thermal_network], every key
// defaulted; docs/model.md, "Self-heating"). Nodes: the coil, the rods (lumped), the
// housing; the ambient is a boundary at a given temperature.
struct ThermalNetworkModel {
  double coil_resistance_ohm = 0;  // at T_ref_C
  double coil_alpha_per_K = 0;     // R(T) = R (1 + alpha (T - T_ref))
  // The winding, for the derived resistance (gmasim/model/derived.hpp); 0: not given.
  double coil_wire_diameter_m = 0, coil_mean_turn_length_m = 0, coil_resistivity_ohm_m = 0;
  double coil_C_J_per_K = 0, rods_C_J_per_K = 0, housing_C_J_per_K = 0;  // heat capacities
  double coil_density_kg_per_m3 = 0, coil_specific_heat_J_per_kg_K = 0;  // the derived coil_C
  double rod_specific_heat_J_per_kg_K = 0;  // rods_C_J_per_K = this x the rods' mass (compile)
  double G_coil_rods_W_per_K = 0, G_coil_housing_W_per_K = 0, G_rods_housing_W_per_K = 0,
         G_housing_ambient_W_per_K = 0;  // thermal conductances
};

// The lengths and expansion coefficients of eq. (21) ([thermal_expansion]); compile() forms
// Model::xT_*_m_per_K from them.
struct ThermalExpansionModel {
  double rod_length_m = 0;  // 0: the longest rod
  double magnetizer_length_m = 0, magnetizer_alpha_per_K = 0;
  double output_rod_length_m = 0, output_rod_alpha_per_K = 0;
  double sleeve_length_m = 0, sleeve_alpha_per_K = 0;
};

// Where the model was validated ([validity], every key defaulted; issue 19, item 8). Outside
// it a run is allowed but warned about (gmasim/model/validity.hpp, temperature_warning).
struct ValidityModel {
  double validated_min_C = 20.0, validated_max_C = 150.0;
};

struct ChainLink {  // one member of a rod's load chain
  enum Kind { Element, Sleeve, Rod } kind;
  int index;
};

struct Model {
  ModelSpec spec;  // kept for `model show` and identification
  Options options;
  Material material;
  std::vector<RodModel> rods;
  Circuit circuit;
  std::vector<int> flux_sensor_branches;
  double flux_sensor_area_m2 = 0.0;
  double T_ref_C = 20.0;   // T_0 of eq. (1), (8); T_r of eq. (4)
  double preload_N = 0.0;  // disk-spring preload through the rod stack
  double alpha_pm1_per_K = 0.0, alpha_pm2_per_K2 = 0.0;
  double Et_Pa = 0.0, dEt_dT_Pa_per_C = 0.0;  // eq. (19) law
  std::vector<ChainElementModel> elements;
  std::vector<SleeveModel> sleeves;
  std::vector<std::vector<ChainLink>> chains;  // per rod
  SensorMountModel sensor_mount;
  ThermalNetworkModel thermal_network;
  ThermalExpansionModel thermal_expansion;
  ValidityModel validity;
  // eq. (21) alpha*l products of the stack [m/K], from thermal_expansion and the rods
  double xT_rod_m_per_K = 0, xT_magnetizer_m_per_K = 0, xT_output_rod_m_per_K = 0,
         xT_sleeve_m_per_K = 0;

  int rod_count() const { return static_cast<int>(rods.size()); }
};

// Validates cross-field rules and builds the typed model. Throws InputError.
Model compile(const ModelSpec& spec);
// The same Model, the spec moved into Model::spec instead of copied (identify compiles a spec
// per parameter point).
Model compile(ModelSpec&& spec);

// ---------------------------------------------------------------------------------------
// Conditions: every temperature-dependent constant at one operating temperature.
// ---------------------------------------------------------------------------------------
struct RodConditions {
  double length_m, area_m2, r_outer_m, r_inner_m;
  double MsT_mu, MsT_mag, MsT_E;           // M_s^T of eq. (4) as seen by eq. (3), the magnetisation
                                           // law (eq. 9) and eq. (11), and eq. (13)
  double Ms_strain_A_per_m;                // the M_s that normalises M in eq. (11) (Eq11Saturation)
  double S_mu_J_per_m3;                    // stress term of eq. (3)
  physics::DeltaETerms dE;                 // eq. (13) constants
  physics::JaCoefficients ja;              // eq. (10) at T (the Jiles-Atherton law)
  physics::PreisachCoefficients preisach;  // the Preisach law's at T
  double rho_ohm_m;                        // eq. (8)
  double eddy_geometry_s_m_per_H;  // kappa of eq. (7): tau = mu kappa; H_c - H = kappa dB/dt
  double alpha_sigma;              // eq. (3) stress terms as a JA coupling S / (mu0 Ms^2) [-]
  double sigma_Pa;                 // signed prestress used in eq. (3), (6), (13)
  double sigma_p_Pa;               // compressive prestress magnitude of eq. (11)
  double k_f, k_j;
  // Consistent magnetic state: the lossless reluctance of the rod's joints in series with the
  // Terfenol-D, g / (mu0 A^T) (physics::joint_reluctance; docs/model.md, "The magnetic
  // state"). 0 in the printed reading.
  double series_reluctance_per_H;
  // The joints' compliance g / (E_j A^T) in series with the rod (options.joint_mechanics =
  // bonded; physics::joint_compliance); 0 for rigid joints.
  double joint_compliance_m_per_N;
  double mass_osc_kg;               // eq. (24) + (27)
  double momentum_mass_kg;          // m/2 + m_lr (eq. 27): the stack's momentum per unit x
  double damping_osc_N_s_per_m;     // eq. (25) + (28)
  double fixed_compliance_m_per_N;  // sum of 1/k of the chain's non-rod members (eq. 18)
  std::array<int, 8> chain_rods;    // rods inside this rod's load chain (eq. 18)
  int chain_rod_count;
  // Reciprocals and ratios of the fields above that every step uses, divided once here
  // (make_conditions sets them with the fields they come from; the step multiplies).
  double inv_area_per_m2;                // 1 / A^T
  double length_over_area_per_m;         // l^T / A^T (eq. 2)
  double area_over_length_m;             // A^T / l^T (eq. 17)
  double inv_MsT_E_m_per_A;              // 1 / MsT_E (eq. 13)
  double inv_Ms_strain_m_per_A;          // 1 / Ms_strain_A_per_m (eq. 11)
  double inv_mass_osc_per_kg;            // 1 / mass_osc_kg (eq. 15)
  double four_sigma_p_over_lambda_s_Pa;  // 4 sigma_p / lambda_s (eq. 11-12's 2 sigma_p/sigma_s x E)
  double ja_inv_a_m_per_A;               // 1 / ja.a_A_per_m (eq. 9; Jiles-Atherton law only)
  double ja_inv_k_m_per_A;               // 1 / ja.k_A_per_m (eq. 9; Jiles-Atherton law only)
};

struct Conditions {
  double temperature_C;
  Freeze freeze;
  double pm_scale;  // F_pm^T / F_pm, eq. (1)
  double Et_Pa;     // eq. (19) modulus
  std::vector<double> sleeve_stiffness_N_per_m;
  std::vector<RodConditions> rods;
  double thermal_expansion_m;  // eq. (21)
};

// Throws InputError if the temperature is at/above T_c or below absolute zero.
Conditions make_conditions(const Model& m, double temperature_C, const Freeze& freeze = {});

// ---------------------------------------------------------------------------------------
// State and step.
// ---------------------------------------------------------------------------------------
// Which stage writes each field ("computed by"): make_state() sets every field; then step()
// (src/model/step.cpp) writes them in the order of its numbered stages:
//   1. the rods' reluctances (eq. 2-3) and the nodal solve of the circuit (eq. 23);
//   2. per rod the static field (eq. 7), the eddy lag (eq. 7) and JA (eq. 9); with the
//      consistent magnetic state, stages 1-2 are one Newton solve (consistent_magnetic_update);
//   3. per rod the strain, modulus and force (eq. 11-14, 17), then the oscillators
//      (eq. 15-18), then the output stage;
//   end: the outputs (eq. 20, the sensors) and the clock.
// rk4_reference_step() writes the same fields by its own integration; quasi_static_step()
// writes every field but t_s as one increment of make_state's ramp does (stages 1-2 without
// eddy lag, then the force and the static equilibrium x = F / K). Nothing else writes a State,
// except run_loop() and run_loop_step() (gmasim/simulate/run_loop.hpp, the latter for the Stepper),
// which set t_s to the grid's time after each step (t0 + k dt: no drift from repeated
// addition), and settle_at_bias (src/experiments/frf.cpp): its anhysteretic start
// (M_irr = M = M_an) and t_s = 0 once the bias point has settled.
struct RodState {
  // integrated state
  double H_A_per_m = 0;     // eddy-filtered field (eq. 7); stage 2: the lag (consistent: Newton)
  double Mirr_A_per_m = 0;  // irreversible magnetisation (eq. 9); stage 2: the JA law's state
  physics::PreisachHistory preisach;  // the Preisach law's state (its extrema); stage 2
  double x_m = 0, v_m_per_s = 0;      // stage 3: oscillator_step (eq. 15); make_state: x = F / K
  // kept for the next step (hold values, warm starts)
  double Hc_A_per_m = 0;       // static field of eq. (7) at the end of the last step; stage 2
  double H_prev_A_per_m = 0;   // H one step earlier (consistent state: Newton's first guess);
                               // stage 2, consistent state only
  double H_prev2_A_per_m = 0;  // H two steps earlier (the same guess, quadratic); stage 2,
                               // consistent state only
  double M_A_per_m = 0;        // total magnetisation consistent with (H, M_irr); stage 2: ja_step
  double M_prev_A_per_m = 0;   // M one step earlier (stage 1's extrapolation; consistent state:
                               // the law's first guess); stage 2
  double M_prev2_A_per_m = 0;  // M two steps earlier (consistent state: the law's first guess)
  double F_N = 0;              // force at the end of the last step (eq. 14); stage 3
  // The Langevin function of eq. (9) where the consistent state's last law evaluation left it:
  // x = H_e / a, L(x), L'(x) (the next move's start M_an from them when near:
  // physics::ja_move_start_near); NaN: none. Stage 2, consistent state, Jiles-Atherton only.
  double an_x = std::numeric_limits<double>::quiet_NaN(), an_L = 0, an_dL = 0;
  // The anchors of the law's exponentials (physics::JaExpPoints, exp_near) where the consistent
  // state's evaluations left them: the next step's evaluations start from them. Stage 2,
  // consistent state, Jiles-Atherton only; none (NaN) after make_state.
  physics::JaExpPoints ja_exp = physics::no_ja_exp_points<double>();
  // reported
  double mu_r = 1;    // eq. (3) at the extrapolated M, stage 1 (printed); the JA differential
                      // permeability 1 + dM/dH, stage 2 (consistent)
  double E_Pa = 0;    // Delta-E modulus (eq. 13); stage 3
  double lambda = 0;  // magnetostriction (eq. 11-12); stage 3
  double tau_s = 0;   // eddy time constant mu kappa (eq. 7); stage 2
  double phi_Wb = 0;  // the rod branch's flux from the circuit (eq. 23); stage 2
  double k_rod_N_per_m = 0;   // axial stiffness (eq. 17); stage 3
  double k_load_N_per_m = 0;  // load-chain stiffness (eq. 18); stage 3
  double B_T = 0;  // the flux density the circuit assigns to the rod, phi / A; end of step()
  double K_osc_N_per_m = 0;  // the oscillator's stiffness over the last step (eq. 16 at mid-step);
                             // stage 3 (make_state: at rest)
  RodEnergy energy;          // the ledgers' running sums (gmasim/model/energy.hpp); end of step()
  // The oscillator's last e^(tau/2) by std::exp (physics::oscillator_propagator): the next step
  // at the same dt reuses it. Stage 3.
  physics::ExpPoint osc_decay = physics::kNoExpPoint;
  // The anchor of eq. (11)'s tanh exponential (physics::magnetostriction_near, exp_near) where
  // the last evaluation left it. Stage 3 (update_rod_mechanics).
  physics::ExpPoint prestress_exp = physics::kNoExpPoint;
};

struct State {
  double t_s = 0;        // end of the last step; end of step(): t_s + dt
  double current_A = 0;  // coil current at t_s; end of step(): StepInput::current_A
  double y_m = 0;        // the output the sensor reads: y_stack - u with a sensor mount (+ x_T
                         // if the option says so); end of step()
  double y_stack_m = 0;  // x1 + x2 + x3 (eq. 20); end of step()
  // Sensor mount (if any): q = p / M, the housing's recoil -x_h; z follows q through the bracket
  // (m z'' + c (z' - q') + k (z - q) = 0), so the probe's deflection is u = q - z; stage 3.
  double q_m = 0, z_m = 0, z_v_m_per_s = 0;
  physics::ExpPoint mount_decay = physics::kNoExpPoint;  // the mount's, as RodState::osc_decay
  double B_T = 0;  // flux density seen by the induction coil (sensor branches); end of step()
  std::vector<RodState> rods;
  CircuitWorkspace circuit;  // stage 1: the rod branches' fluxes phi (eq. 23), the consistent
                             // state's linearised rod MMFs (rod_extra_mmf)
  std::vector<double> rod_reluctance;  // per rod, eq. (2) (consistent: linearised); stage 1
  EnergyAccumulators
      energy;  // the ledgers (gmasim/model/energy.hpp): booked by step() when enabled
  // Statistics: circuit solves of the consistent magnetic state's Newton method (one per
  // iteration), summed over the steps since make_state (quasi-static moves included).
  long newton_solves = 0;
};

// Sizes every buffer, and places the actuator at rest in its quasi-static equilibrium
// under current_A, demagnetised (M_irr = 0) before the field is applied.
State make_state(const Model& m, const Conditions& c, double current_A);
// The same with the quasi-static ramp in `ramp_increments` equal increments of the current and
// the magnets' MMF (make_state: kRestRampSteps, gmasim/model/step_stages.hpp); the rest state
// converges at second order in the increment (tests/test_model.cpp,
// RestState.RampConvergesAtSecondOrder). Throws InputError for ramp_increments < 1.
State make_state(const Model& m, const Conditions& c, double current_A, int ramp_increments);

// Moves the actuator quasi-statically (the limit of a vanishing frequency) to current_A:
// the magnetic state follows its hysteresis loop without eddy lag (eq. 7 with dB/dt = 0,
// eq. 9 over the increment) and the mechanics settle at the static equilibrium x = F / K
// (eq. 15 with x'' = x' = 0); t_s is not advanced. The accuracy of the loop depends on the
// increment of the field per call (eq. 9 is integrated with a first-order hold): callers
// sub-divide large changes of current (identify's quasi-static records do). Allocation-free.
// Throws DivergenceError.
void quasi_static_step(const Model& m, const Conditions& c, State& s, double current_A);

struct StepInput {
  double current_A;  // coil current at the end of the step
  double dt_s;       // step length
};

// Advances the state by one step. Allocation-free. Throws DivergenceError. Dispatches on
// options.magnetisation_law at each call; a time loop dispatches once (run_loop.hpp) and calls
// step_law<Law> (the same step, compiled for one law: gmasim/magnetisation/laws.hpp).
void step(const Model& m, const Conditions& c, State& s, const StepInput& in);
struct JilesAthertonLaw;
struct PreisachLaw;
template <class Law>
void step_law(const Model& m, const Conditions& c, State& s, const StepInput& in);
template <class Law>
void quasi_static_step_law(const Model& m, const Conditions& c, State& s, double current_A);
extern template void step_law<JilesAthertonLaw>(const Model&, const Conditions&, State&,
                                                const StepInput&);
extern template void step_law<PreisachLaw>(const Model&, const Conditions&, State&,
                                           const StepInput&);
extern template void quasi_static_step_law<JilesAthertonLaw>(const Model&, const Conditions&,
                                                             State&, double);
extern template void quasi_static_step_law<PreisachLaw>(const Model&, const Conditions&, State&,
                                                        double);

// Reference integrator: one plain explicit RK4 step of the same equations, with the state
// (H, M_irr, x, v) of every rod integrated as an ODE in time and the circuit solved at each
// stage. Stable only for dt below ~20 us (the 7-20 kHz mechanical modes); used by tests
// and benchmarks to validate step() and to measure what the exact updates save.
// Allocation-free like step().
void rk4_reference_step(const Model& m, const Conditions& c, State& s, double current0_A,
                        double current_mid_A, double current1_A, double dt_s);

// Static stiffness of rod i's oscillator (eq. 16-18) at the state's magnetisation.
double oscillator_stiffness(const Conditions& c, const State& s, int rod);

}  // namespace gmasim
