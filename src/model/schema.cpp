// The rules of the parameter table applied to a spec, and ModelSpec::get/set/set_option/
// line_of: the rules a parameter obeys wherever it is set (the loader of src/io, --set,
// identify).
#include "model/schema.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "gmasim/errors.hpp"

namespace gmasim {

// =======================================================================================
// Schema: the rows of gmasim/model/parameters.hpp applied to a spec
// =======================================================================================
namespace schema {
namespace {

// The tables of a model file that hold structure; the others are the parameter groups'.
constexpr std::string_view kStructureTables[] = {"meta",   "options",   "stack",      "circuit",
                                                 "sensor", "mechanics", "calibration"};

// The table part of a dotted name ("rod1.ja" of "rod1.ja.k0_A_per_m").
std::string table_of(const std::string& dotted) {
  const auto dot = dotted.rfind('.');
  return dot == std::string::npos ? std::string() : dotted.substr(0, dot);
}

// The dotted name of the parameter a cross rule names, seen from the table of `dotted`.
std::string other_of(const CrossRule& c, const std::string& dotted) {
  if (c.other.find('.') != std::string_view::npos) return std::string(c.other);
  return table_of(dotted) + "." + std::string(c.other);
}

}  // namespace

const std::vector<std::string>& reserved_tables() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v(std::begin(kStructureTables), std::end(kStructureTables));
    for (const auto& g : parameter_groups()) {
      const std::string top(g.path.substr(0, g.path.find('.')));
      if (!top.starts_with('<') && std::find(v.begin(), v.end(), top) == v.end()) v.push_back(top);
    }
    return v;
  }();
  return names;
}

std::vector<std::string> group_instances(const ModelSpec& spec, Group g) {
  switch (g) {
    case Group::Rod:
      return spec.rods;
    case Group::RodJa:
    case Group::RodPreisach:  // a magnetisation law's: only in a model that selects it
      return group_def(g).law == spec.options.magnetisation_law ? spec.rods
                                                                : std::vector<std::string>{};
    case Group::Element:
      return spec.element_names;
    case Group::Sleeve:
      return spec.sleeve_names;
    case Group::Branch: {
      std::vector<std::string> names;
      for (const auto& b : spec.branches) names.push_back(b.name);
      return names;
    }
    case Group::Reluctance:
      return {};
    case Group::ReluctanceGeometry:
      return spec.reluctance_geometry_names;
    case Group::SensorMount: {  // present when the spec holds any of its numbers
      const std::string prefix = table_path(Group::SensorMount, "") + ".";
      const auto it = spec.params.lower_bound(prefix);
      if (it == spec.params.end() || !it->first.starts_with(prefix)) return {};
      return {""};
    }
    default:
      return {""};
  }
}

std::string table_path(Group g, std::string_view instance) {
  const std::string_view path = group_def(g).path;
  const auto open = path.find('<');
  if (open == std::string_view::npos) return std::string(path);
  const auto close = path.find('>', open);
  return std::string(path.substr(0, open)) + std::string(instance) +
         std::string(path.substr(close + 1));
}

std::string value_with_unit(const std::string& dotted, double value, const std::string& unit) {
  if (unit.empty() || unit == "-") return fmt::format("{} = {:g}", dotted, value);
  return fmt::format("{} = {:g} {}", dotted, value, unit);
}

std::optional<std::string> check_value(const ModelSpec& spec, const std::string& dotted,
                                       double value) {
  const ParamDef* def = find_param_def(spec, dotted);
  const std::string unit = def ? std::string(def->unit) : std::string("-");
  auto bad = [&](std::string_view rule) {
    return fmt::format("{}: {}", value_with_unit(dotted, value, unit), rule);
  };
  if (auto problem = number_problem(value)) return bad(*problem);
  if (!def) return std::nullopt;
  if (!rule_holds(def->rule, value)) return bad(rule_message(def->rule));
  if (def->cross.kind == CrossRule::None) return std::nullopt;
  const std::string other = other_of(def->cross, dotted);
  const auto it = spec.params.find(other);
  if (it == spec.params.end() || !std::isfinite(it->second.value)) return std::nullopt;
  const bool below = def->cross.kind == CrossRule::Below;
  if (below ? value < it->second.value : value > it->second.value) return std::nullopt;
  return bad(fmt::format("must be {} {}", below ? "<" : ">",
                         value_with_unit(other, it->second.value, spec.unit_of(other))));
}

std::vector<std::string> dependents(const ModelSpec& spec, const std::string& dotted) {
  std::vector<std::string> out;
  const ParamDef* def = find_param_def(spec, dotted);
  if (!def) return out;
  for (const auto& row : parameter_table()) {
    if (row.cross.kind == CrossRule::None) continue;
    const bool sibling = row.cross.other.find('.') == std::string_view::npos;
    if (sibling ? (row.group == def->group && row.cross.other == def->key)
                : row.cross.other == dotted) {
      for (const auto& inst : group_instances(spec, row.group)) {
        const std::string name = table_path(row.group, inst) + "." + std::string(row.key);
        if (!sibling || table_of(name) == table_of(dotted)) out.push_back(name);
      }
    }
  }
  return out;
}

bool is_unset(const ParamValue& pv) { return pv.line == 0 && std::isnan(pv.value); }

std::vector<std::string> unset_parameters(const ModelSpec& spec) {
  std::vector<std::string> names;
  for (const auto& [name, pv] : spec.params)
    if (is_unset(pv)) names.push_back(name);
  return names;
}

std::optional<std::string> unset_message(const ModelSpec& spec) {
  const auto names = unset_parameters(spec);
  if (names.empty()) return std::nullopt;
  std::string law;
  for (const auto& def : option_table())
    if (def.key == "magnetisation_law") law = option_word(def, spec.options);
  return fmt::format(
      "options.magnetisation_law = \"{}\": the model file has no numbers of this law; missing {} "
      "(give each with --set name=value, e.g. --set {}=..., or write the law's table into the "
      "file; docs/parameters.md lists them)",
      law, fmt::join(names, ", "), names.front());
}

}  // namespace schema

// =======================================================================================
// ModelSpec accessors
// =======================================================================================
namespace {

// Exact name, else the unique dimensionless parameter "<dotted>_<rest>" ("material.lambda" ->
// "material.lambda_s"); nullopt if none; throws if the prefix is ambiguous, or if it names a
// dimensional parameter without its unit suffix (issue 19, item 9: "rod1.length" would be read
// in metres unseen; the user must write "rod1.length_m").
std::optional<std::string> try_resolve(const ModelSpec& spec, const std::string& dotted) {
  if (spec.params.count(dotted)) return dotted;
  const std::string prefix = dotted + "_";
  std::vector<std::string> matches;
  for (auto it = spec.params.lower_bound(prefix);
       it != spec.params.end() && it->first.starts_with(prefix); ++it) {
    if (it->first.find('.', prefix.size()) == std::string::npos) matches.push_back(it->first);
  }
  if (matches.size() == 1) {
    const std::string unit = spec.unit_of(matches.front());
    if (unit != "-")
      throw InputError(
          located(spec.source, 0,
                  fmt::format("parameter '{}' has a unit: write '{}' (the value in {}); every "
                              "dimensional key carries its unit suffix",
                              dotted, matches.front(), unit)));
    return matches.front();
  }
  if (matches.size() > 1) {
    throw InputError(located(
        spec.source, 0,
        fmt::format("ambiguous parameter '{}': matches {}", dotted, fmt::join(matches, ", "))));
  }
  return std::nullopt;
}

[[noreturn]] void throw_unknown(const ModelSpec& spec, const std::string& dotted) {
  // The deepest group of the name that exists ("rod1.ja."), else the top-level groups.
  std::string group = dotted;
  while (true) {
    const auto dot = group.rfind('.');
    if (dot == std::string::npos) break;
    group.resize(dot + 1);
    std::vector<std::string> names;
    for (auto it = spec.params.lower_bound(group);
         it != spec.params.end() && it->first.starts_with(group); ++it) {
      names.push_back(it->first);
    }
    if (!names.empty()) {
      if (names.size() > 12) {
        names.resize(12);
        names.emplace_back("...");
      }
      throw InputError(
          located(spec.source, 0,
                  fmt::format("unknown parameter '{}'; known parameters start with {}: {}", dotted,
                              group, fmt::join(names, ", "))));
    }
    group.pop_back();  // drop the '.' and look one level up
  }
  std::vector<std::string> groups;
  for (const auto& [name, pv] : spec.params) {
    const std::string g = name.substr(0, name.find('.') + 1);
    if (groups.empty() || groups.back() != g) groups.push_back(g);
  }
  throw InputError(located(spec.source, 0,
                           fmt::format("unknown parameter '{}'; known parameters start with {}",
                                       dotted, fmt::join(groups, ", "))));
}

std::string resolve(const ModelSpec& spec, const std::string& dotted) {
  if (auto key = try_resolve(spec, dotted)) return *key;
  throw_unknown(spec, dotted);
}

}  // namespace

std::string ModelSpec::key_of(const std::string& dotted) const { return resolve(*this, dotted); }

double ModelSpec::get(const std::string& dotted) const {
  return params.at(resolve(*this, dotted)).value;
}

namespace {

// Setting one of a pair of alternative keys (preload.force_N | preload.prestress_MPa) that
// the spec does not hold replaces the other: the spec holds one of them.
bool swap_alternative(ModelSpec& spec, const std::string& dotted, double value) {
  if (spec.params.count(dotted)) return false;
  const ParamDef* def = find_param_def(spec, dotted);
  if (!def || def->alternative.empty()) return false;
  const std::string other =
      dotted.substr(0, dotted.rfind('.')) + "." + std::string(def->alternative);
  const auto it = spec.params.find(other);
  if (it == spec.params.end()) return false;
  ParamValue pv = it->second;
  if (auto problem = schema::check_value(spec, dotted, value))
    throw InputError(located(spec.source, pv.line,
                             fmt::format("cannot set {} = {:g}: {}", dotted, value, *problem)));
  pv.value = value;
  pv.provenance = fmt::format("set in place of {}", other);
  spec.params.erase(it);
  spec.params[dotted] = std::move(pv);
  return true;
}

// A change of magnetisation law swaps the rods' law groups: the old law's numbers leave the
// spec, the new law's rows enter it unset (NaN, line 0: schema::is_unset) or at their default.
void swap_law_groups(ModelSpec& spec, MagnetisationLaw from, MagnetisationLaw to) {
  for (const GroupDef& g : parameter_groups()) {
    if (!g.law || (*g.law != from && *g.law != to)) continue;
    const std::string leaf(g.path.substr(g.path.rfind('.') + 1));
    for (const auto& rod : spec.rods) {
      const std::string prefix = rod + "." + leaf + ".";
      if (*g.law == from) {
        auto it = spec.params.lower_bound(prefix);
        while (it != spec.params.end() && it->first.starts_with(prefix)) it = spec.params.erase(it);
        continue;
      }
      for (const ParamDef& row : parameter_table()) {
        if (row.group != g.group) continue;
        ParamValue pv;
        pv.value = row.default_value.value_or(std::numeric_limits<double>::quiet_NaN());
        spec.params.emplace(prefix + std::string(row.key), pv);
      }
    }
  }
}

}  // namespace

void ModelSpec::set(const std::string& dotted, double value) {
  if (swap_alternative(*this, dotted, value)) return;
  const std::string key = resolve(*this, dotted);
  ParamValue& pv = params.at(key);
  const double old = pv.value;
  const bool was_assigned = pv.assigned;
  pv.value = value;
  pv.assigned = true;  // a value set is the user's: never replaced by a derivation
  const std::string was_provenance = pv.provenance;
  if (!was_assigned && pv.line == 0 && pv.provenance.starts_with("derived:"))
    pv.provenance = "set in place of the derived value";
  // The value itself, and the cross-field rules that depend on it.
  std::vector<std::string> to_check = {key};
  for (auto& d : schema::dependents(*this, key)) to_check.push_back(std::move(d));
  for (const auto& k : to_check) {
    const auto it = params.find(k);
    if (it == params.end() || schema::is_unset(it->second)) continue;
    if (auto problem = schema::check_value(*this, k, it->second.value)) {
      pv.value = old;
      pv.assigned = was_assigned;
      pv.provenance = was_provenance;
      throw InputError(
          located(source, pv.line, fmt::format("cannot set {} = {:g}: {}", key, value, *problem)));
    }
  }
}

void ModelSpec::set_options(const std::vector<std::pair<std::string, std::string>>& name_word) {
  Options changed = options;
  for (const auto& [name, word] : name_word) {
    const OptionDef* def = find_option_def(name);
    if (!def) {
      std::string known;
      for (const auto& o : option_table())
        known += (known.empty() ? "" : ", ") + std::string("options.") + std::string(o.key);
      throw InputError(
          located(source, 0, fmt::format("unknown option '{}'; known: {}", name, known)));
    }
    if (auto problem = set_option_word(*def, changed, word))
      throw InputError(located(source, line_of("options." + std::string(def->key)), *problem));
  }
  if (auto problem = check_options(changed))
    throw InputError(located(source, line_of(problem->key), problem->message));
  if (changed.magnetisation_law != options.magnetisation_law)
    swap_law_groups(*this, options.magnetisation_law, changed.magnetisation_law);
  options = changed;
}

const ParamDef* ModelSpec::def_of(const std::string& key) const {
  return find_param_def(*this, key);
}

std::string ModelSpec::unit_of(const std::string& key) const {
  const ParamDef* def = def_of(key);
  return def ? std::string(def->unit) : std::string("-");
}

long ModelSpec::line_of(const std::string& dotted) const {
  if (const auto it = option_lines.find(dotted); it != option_lines.end()) return it->second;
  try {
    if (auto key = try_resolve(*this, dotted)) return params.at(*key).line;
  } catch (const InputError&) {
    return 0;  // ambiguous prefix: no single line
  }
  return 0;
}

}  // namespace gmasim
