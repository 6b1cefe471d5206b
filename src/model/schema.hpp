// Internal: the model-file schema (field lists, units, value rules) shared by the loader
// (src/io), ModelSpec::set and describe_model. Not part of the public API.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "gmasim/model.hpp"

namespace gmasim::schema {

// Single-field value rules of the schema.
enum class Rule {
  Any,               // any finite number
  Positive,          // > 0
  NonNegative,       // >= 0
  UnitInterval,      // [0, 1)
  AboveAbsoluteZero  // > -273.15 degC
};

struct Field {
  std::string_view key;
  Rule rule;
  std::string_view unit = {};  // empty: from the key suffix
};

// Top-level tables with fixed names (a rod may not use one of these names).
std::span<const std::string_view> reserved_tables();

// Field lists of the fixed tables.
std::span<const Field> reference_fields();
std::span<const Field> material_fields();
std::span<const Field> preload_fields();
std::span<const Field> magnet_fields();
std::span<const Field> rod_fields();
std::span<const Field> ja_fields();
std::span<const Field> element_fields();
std::span<const Field> sleeve_modulus_fields();
std::span<const Field> output_stage_fields();
std::span<const Field> sleeve_fields();
std::span<const Field> branch_number_fields();
// A field that may be absent: its default value and the provenance shown for it.
struct DefaultedField {
  Field field;
  double value;
  std::string_view provenance;
};
std::span<const DefaultedField> thermal_network_defaults();
std::span<const DefaultedField> magnet_defaults();
std::span<const DefaultedField> sleeve_modulus_defaults();
std::span<const DefaultedField> thermal_expansion_defaults();
inline constexpr Field kReluctanceField{"", Rule::Positive, "1/H"};

// Unit of a key: the field's explicit unit, else the suffix table ("_A_per_m" -> "A/m"),
// else "-" (dimensionless).
std::string unit_of(const Field& f);
std::string unit_from_suffix(std::string_view key);

// The rule of a stored parameter, found from its dotted name; nullopt if the name does
// not fit the schema.
std::optional<Field> field_of(const ModelSpec& spec, const std::string& dotted);

// Checks `value` for parameter `dotted` against its rule and the cross-field rules
// (inner < outer diameter, Tc > T_ref) using the other values in `spec`. Returns the
// problem "<dotted> = <value> <unit>: <rule>" or nullopt.
std::optional<std::string> check_value(const ModelSpec& spec, const std::string& dotted,
                                       double value);

// "name = value unit" formatted for messages ({:g}; unit omitted when "-").
std::string value_with_unit(const std::string& dotted, double value, const std::string& unit);

}  // namespace gmasim::schema
