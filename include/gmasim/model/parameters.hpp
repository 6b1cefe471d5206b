// The parameter table: every number and option a model file may hold, one row each, with
// its unit, rule, meaning and the place in Model it lands (issue 10, "one place per fact").
// The loader (src/io/model_loader.cpp), compile(), ModelSpec::set/set_option, `gmasim model
// show`, identify's parameter names and docs/parameters.md (`gmasim model params
// --markdown`) all read these tables; adding a parameter is one TOML line and one row of
// src/model/parameters.cpp (plus the Model field it lands in).
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "gmasim/magnetisation/law_id.hpp"

namespace gmasim {

struct Model;
struct ModelSpec;
struct Options;
struct ParamDef;

// Every number of a model file is finite and, unless 0, within these magnitudes: no SI value
// of the model lies outside (the smallest, eq. 1's alpha_pm2, is ~1e-7 /K^2; the largest, a
// modulus, ~1e11 Pa), so such a number is a typo or a hostile input, and a subnormal one turns
// into inf/NaN downstream (issue 8).
inline constexpr double kMinMagnitude = 1e-30, kMaxMagnitude = 1e30;
// Why `value` is no number of a model file (NaN, Inf, out of the magnitudes), or nullopt.
std::optional<std::string> number_problem(double value);

// The value rule of a number, besides number_problem().
enum class Rule {
  Any,               // any finite number
  Positive,          // > 0
  NonNegative,       // >= 0
  UnitInterval,      // [0, 1)
  AboveAbsoluteZero  // > -273.15 degC
};
std::string_view rule_text(Rule r);  // "> 0", ">= 0", "[0, 1)", "> -273.15 degC", "any"
// The whole rule of a row: its Rule and its cross-field rule ("any, > reference.T_ref_C").
std::string row_rule_text(const ParamDef& row);
bool rule_holds(Rule r, double value);  // whether a finite value obeys r
std::string rule_message(Rule r);       // "must be > 0", "must be in [0, 1)", ...

// The tables of a model file that hold numbers.
enum class Group {
  Reference,           // [reference]
  Material,            // [material]: Terfenol-D, shared by the rods
  Preload,             // [preload]
  Magnet,              // [magnet] (optional, every key defaulted)
  Rod,                 // [<rod>] for each rod of stack.rods
  RodJa,               // [<rod>.ja] (the Jiles-Atherton law)
  RodPreisach,         // [<rod>.preisach] (the Preisach law)
  Element,             // [mechanics.elements.<name>]
  SensorMount,         // [mechanics.sensor_mount] (optional)
  SleeveModulus,       // [mechanics.sleeve_modulus] (optional, every key defaulted)
  Sleeve,              // [mechanics.sleeves.<name>]
  Branch,              // [[circuit.branches]] (numbers optional, absent = 0)
  Reluctance,          // [circuit.reluctances_per_H] (free names)
  ReluctanceGeometry,  // [circuit.reluctance_geometry.<name>]: derives a fixed reluctance
  ThermalExpansion,    // [thermal_expansion] (optional, every key defaulted)
  ThermalNetwork,      // [thermal_network] (optional, every key defaulted)
  Validity             // [validity] (optional, every key defaulted)
};

// Whether a group's table must be in the file.
enum class TableRule {
  Required,     // missing table: an error; every key without a default is required
  Optional,     // may be absent (then the feature is off); if present, every key is required
  Defaulted,    // may be absent, as may any key: the row's default stands in (line 0)
  KeysOptional  // the table is structure read elsewhere; a number absent from it is 0
};

struct GroupDef {
  Group group;
  std::string_view path;  // dotted path of its table; "<rod>", "<name>" stand for instances
  TableRule table;
  std::string_view doc;
  // A magnetisation law's group: read, required and landed only in a model that selects the
  // law (options.magnetisation_law); absent: every model's.
  std::optional<MagnetisationLaw> law = std::nullopt;
};

// A cross-field rule: the value must lie below / above another parameter's value. `other` is
// a key of the same table (no '.') or a full dotted name.
struct CrossRule {
  enum Kind { None, Below, Above } kind = None;
  std::string_view other = {};
};

// Where a number lands in the compiled Model: a reference to the field for instance i of the
// row's group (the rod, element, sleeve or branch index; 0 for single tables); null for
// [circuit.reluctances_per_H], whose values compile() sums per branch.
using LandFn = double& (*)(Model&, std::size_t instance);

struct ParamDef {
  Group group;
  std::string_view key;   // e.g. "Ms_A_per_m"; "*" for any name (Reluctance)
  std::string_view unit;  // "A/m", "-" for dimensionless
  Rule rule;
  std::string_view doc;       // what it is, with the paper's equation or table
  LandFn lands;               // where it lands in Model
  std::string_view lands_in;  // the same as text, e.g. "Material::Ms_A_per_m"
  std::optional<double> default_value = std::nullopt;  // Defaulted tables only
  std::string_view default_provenance = {};            // shown by `model show` for a default
  CrossRule cross = {};
  // A key of the same table that may stand in for this one (preload.force_N and
  // preload.prestress_MPa): a file gives exactly one of the two; the spec holds the one given.
  std::string_view alternative = {};
};

// One value of an option: its word in the file and what it means.
struct OptionChoice {
  std::string_view word;  // "printed"; booleans: "false" / "true"
  int value;              // the enum value (or 0 / 1)
  std::string_view doc;
};

// An option: a reading of the paper or a switch, a word from a fixed list (or a boolean),
// parsed once into the enum of Options.
struct OptionDef {
  std::string_view key;  // e.g. "magnetic_state" (in [options])
  bool boolean;          // TOML true/false rather than a string
  std::span<const OptionChoice> choices;
  void (*lands)(Options&, int value);
  int (*reads)(const Options&);
  std::string_view lands_in;  // "Options::magnetic_state"
  std::string_view doc;
  // The word a model file may omit the option with (empty: the option is required).
  std::string_view default_word = {};
};

std::span<const GroupDef> parameter_groups();
std::span<const ParamDef> parameter_table();
std::span<const OptionDef> option_table();
const GroupDef& group_def(Group g);

// The row of a stored parameter, from its dotted name ("rod2.ja.k0_A_per_m": the RodJa row
// k0_A_per_m), given the spec's rods; nullptr if the name fits no row.
const ParamDef* find_param_def(const ModelSpec& spec, std::string_view dotted);
// The row of option `key` ("magnetic_state" or "options.magnetic_state"); nullptr if none.
const OptionDef* find_option_def(std::string_view key);

// The word of option `def` in `o` ("consistent"), and its parse: the value of `word`, or an
// InputError-ready problem "options.<key> = \"<word>\": must be one of: a, b".
std::string_view option_word(const OptionDef& def, const Options& o);
std::optional<std::string> set_option_word(const OptionDef& def, Options& o, std::string_view word);
// Rules that span options (e.g. eq10_shape_law = mean_field needs room_referenced): the
// problem and the key it concerns, or nullopt.
struct OptionProblem {
  std::string key, message;
};
std::optional<OptionProblem> check_options(const Options& o);

// The whole table as Markdown (docs/parameters.md): groups, rows, options.
std::string parameters_markdown();

}  // namespace gmasim
