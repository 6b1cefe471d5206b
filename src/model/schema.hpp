// Internal: the rules of the parameter table (gmasim/model/parameters.hpp) applied to a ModelSpec,
// shared by the loader (src/io), compile() and ModelSpec::set. Not part of the public API.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gmasim/model/model.hpp"

namespace gmasim::schema {

// Top-level tables with fixed names (a rod may not use one of these names).
const std::vector<std::string>& reserved_tables();

// The instances of a group in a spec: the rod, element, sleeve or branch names; {""} for a
// single table; {} for an optional table the spec does not have (output stage) and for
// [circuit.reluctances_per_H], whose names are its keys.
std::vector<std::string> group_instances(const ModelSpec& spec, Group g);

// The dotted table path of instance `instance` of group `g` ("rod2.ja" for RodJa, "rod2").
std::string table_path(Group g, std::string_view instance);

// Checks `value` for parameter `dotted` against its row's rule and cross-field rule
// (inner < outer diameter, Tc > T_ref) using the other values in `spec`. Returns the
// problem "<dotted> = <value> <unit>: <rule>" or nullopt.
std::optional<std::string> check_value(const ModelSpec& spec, const std::string& dotted,
                                       double value);

// The parameters whose cross-field rule refers to `dotted` (set() re-checks them).
std::vector<std::string> dependents(const ModelSpec& spec, const std::string& dotted);

// "name = value unit" formatted for messages ({:g}; unit omitted when "-").
std::string value_with_unit(const std::string& dotted, double value, const std::string& unit);

// A number the spec needs but nobody has given: the rows of a magnetisation law's group that
// enter the spec when options.magnetisation_law changes to it (ModelSpec::set_options) and
// that the file does not hold; NaN on line 0 until --set (ModelSpec::set) gives them.
bool is_unset(const ParamValue& pv);
// The unset numbers of a spec by dotted name, and the message that names them (nullopt if
// none): compile() and `gmasim model save` refuse such a spec with it.
std::vector<std::string> unset_parameters(const ModelSpec& spec);
std::optional<std::string> unset_message(const ModelSpec& spec);

}  // namespace gmasim::schema
