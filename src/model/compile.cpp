// ModelSpec -> Model: the numbers land where the parameter table says
// (gmasim/model/parameters.hpp), then the structure (circuit, sensor, load chains) is assembled and
// the derived quantities formed.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/model/derived.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/model/validity.hpp"
#include "model/schema.hpp"

namespace gmasim {
namespace {

[[noreturn]] void fail(const ModelSpec& spec, long line, const std::string& msg) {
  throw InputError(located(spec.source, line, msg));
}

// The rules of every number and of the options, as the loader applies them: a spec built or
// edited in code is held to the same rules as a file.
void check_spec(const ModelSpec& spec, const std::vector<std::string>& derived) {
  if (auto missing = schema::unset_message(spec)) fail(spec, 0, *missing);
  for (const auto& [name, pv] : spec.params) {
    if (std::find(derived.begin(), derived.end(), name) != derived.end()) continue;
    if (auto problem = schema::check_value(spec, name, pv.value)) fail(spec, pv.line, *problem);
  }
  if (auto problem = check_options(spec.options))
    fail(spec, spec.line_of(problem->key), problem->message);
}

int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

// One Model member per instance of the groups (rods, elements, sleeves, branches), named.
void size_instances(const ModelSpec& spec, Model& m) {
  if (spec.rods.empty()) fail(spec, 0, "stack.rods is empty: at least one rod is required");
  if (spec.rods.size() > 8) fail(spec, 0, "stack.rods lists more than 8 rods");
  m.rods.resize(spec.rods.size());
  for (std::size_t i = 0; i < spec.rods.size(); ++i) m.rods[i].name = spec.rods[i];
  m.elements.resize(spec.element_names.size());
  for (std::size_t i = 0; i < spec.element_names.size(); ++i)
    m.elements[i].name = spec.element_names[i];
  m.sleeves.resize(spec.sleeve_names.size());
  for (std::size_t i = 0; i < spec.sleeve_names.size(); ++i)
    m.sleeves[i].name = spec.sleeve_names[i];
  m.circuit.branches.resize(spec.branches.size());
  for (std::size_t i = 0; i < spec.branches.size(); ++i)
    m.circuit.branches[i].name = spec.branches[i].name;
}

// Every row of the parameter table, for every instance of its group: the spec's value
// lands in the Model field the row names. A number absent from the spec takes the row's
// default (Defaulted tables) or stays 0 (the optional numbers of a branch).
void land_parameters(const ModelSpec& spec, Model& m) {
  // The table paths of the row's group instances with their dot ("rod2.ja."), formed once per
  // run of rows of one group (the table lists a group's rows together).
  std::optional<Group> group;
  std::vector<std::string> prefixes;
  std::string name;
  for (const ParamDef& row : parameter_table()) {
    if (row.lands == nullptr) continue;  // [circuit.reluctances_per_H]: summed per branch
    if (group != row.group) {
      group = row.group;
      prefixes.clear();
      for (const auto& instance : schema::group_instances(spec, row.group))
        prefixes.push_back(schema::table_path(row.group, instance) + ".");
    }
    const TableRule table = group_def(row.group).table;
    const bool alternative = !row.alternative.empty();  // absent: its alternative is given
    for (std::size_t i = 0; i < prefixes.size(); ++i) {
      name.assign(prefixes[i]).append(row.key);
      const auto it = spec.params.find(name);
      if (it != spec.params.end())
        row.lands(m, i) = it->second.value;
      else if (row.default_value)
        row.lands(m, i) = *row.default_value;
      else if (table != TableRule::KeysOptional && !alternative)
        row.lands(m, i) = spec.get(name);  // throws: unknown parameter
    }
  }
}

// The netlist of eq. (23): nodes, branch ends, rod branches and the fixed reluctances.
void build_circuit(const ModelSpec& spec, Model& m) {
  Circuit& c = m.circuit;
  c.reference_node = spec.reference_node;
  c.node_names = spec.nodes;
  for (const auto& n : spec.nodes)
    if (n == spec.reference_node)
      fail(spec, spec.nodes_line,
           fmt::format("circuit.nodes lists the reference node '{}'; list only the others", n));
  auto node_index = [&](const std::string& name, const SpecBranch& b) -> int {
    if (name == spec.reference_node) return -1;
    const int k = index_of(spec.nodes, name);
    if (k < 0)
      fail(spec, b.line,
           fmt::format("circuit branch '{}' names node '{}', which is neither in "
                       "circuit.nodes nor the reference node '{}'",
                       b.name, name, spec.reference_node));
    return k;
  };
  std::vector<const SpecBranch*> branch_of_rod(spec.rods.size(), nullptr);
  for (std::size_t k = 0; k < spec.branches.size(); ++k) {
    const SpecBranch& b = spec.branches[k];
    CircuitBranch& cb = c.branches[k];
    cb.from = node_index(b.from, b);
    cb.to = node_index(b.to, b);
    if (!b.rod.empty()) {
      cb.rod = index_of(spec.rods, b.rod);
      if (cb.rod < 0)
        fail(spec, b.line,
             fmt::format("circuit branch '{}' names rod '{}', which is not in stack.rods", b.name,
                         b.rod));
      // Each rod in exactly one branch, said with names and lines (issue 19, item 11).
      const SpecBranch*& first = branch_of_rod[static_cast<std::size_t>(cb.rod)];
      if (first)
        fail(spec, b.line,
             fmt::format("circuit branch '{}' carries rod '{}', which branch '{}' (line {}) "
                         "already carries: each rod of stack.rods is in exactly one branch",
                         b.name, b.rod, first->name, first->line));
      first = &b;
    } else {
      for (const auto& s : b.series)
        cb.fixed_reluctance_per_H += spec.get("circuit.reluctances_per_H." + s);
    }
  }
  for (std::size_t r = 0; r < spec.rods.size(); ++r)
    if (!branch_of_rod[r])
      fail(spec, spec.line_of("stack.rods"),
           fmt::format("rod '{}' of stack.rods is in no circuit branch: add a "
                       "[[circuit.branches]] with rod = \"{}\"",
                       spec.rods[r], spec.rods[r]));
  // No coil, no drive: every current would give stroke 0 and a copper loss (issue 41).
  if (std::none_of(c.branches.begin(), c.branches.end(),
                   [](const CircuitBranch& b) { return b.coil_turns > 0.0; }))
    fail(spec, spec.branches.empty() ? 0 : spec.branches.front().line,
         "no circuit branch carries a coil (coil_turns > 0 in one of [[circuit.branches]]): the "
         "coil current would drive nothing; give the drive coil's branch its turns");
  finalize_circuit(c, m.rod_count(), spec.source);
}

// The induction coil: the rod branches whose flux it encloses.
void build_flux_sensor(const ModelSpec& spec, Model& m) {
  const auto& branches = m.circuit.branches;
  for (const auto& name : spec.flux_sensor_branches) {
    auto it = std::find_if(branches.begin(), branches.end(),
                           [&](const CircuitBranch& b) { return b.name == name; });
    if (it == branches.end())
      fail(spec, 0, fmt::format("sensor.flux_branches names unknown branch '{}'", name));
    if (it->rod < 0)
      fail(spec, 0,
           fmt::format("sensor.flux_branches: branch '{}' is not a rod branch; the coil's "
                       "flux density is the rod flux over the rod area",
                       name));
    m.flux_sensor_branches.push_back(static_cast<int>(it - branches.begin()));
  }
  if (m.flux_sensor_branches.empty()) fail(spec, 0, "sensor.flux_branches is empty");
}

// The members of one rod's load chain (eq. 18, 27, 28).
std::vector<ChainLink> build_chain(const ModelSpec& spec, const Model& m, std::size_t i,
                                   const std::vector<std::string>& members) {
  const std::string& rod = m.rods[i].name;
  std::vector<ChainLink> chain;
  for (const auto& name : members) {
    ChainLink link{ChainLink::Element, index_of(spec.element_names, name)};
    if (link.index < 0) link = {ChainLink::Sleeve, index_of(spec.sleeve_names, name)};
    if (link.index < 0) link = {ChainLink::Rod, index_of(spec.rods, name)};
    if (link.index < 0)
      fail(spec, 0,
           fmt::format("mechanics.chains.{} names '{}', which is no element, sleeve or rod", rod,
                       name));
    if (link.kind == ChainLink::Rod && link.index == static_cast<int>(i))
      fail(spec, 0, fmt::format("mechanics.chains.{} contains the rod itself", rod));
    chain.push_back(link);
  }
  if (chain.empty())
    fail(spec, 0,
         fmt::format("mechanics.chains.{} is empty: the rod needs a load path (eq. 18)", rod));
  return chain;
}

void build_chains(const ModelSpec& spec, Model& m) {
  m.chains.resize(m.rods.size());
  for (std::size_t i = 0; i < m.rods.size(); ++i) {
    auto it = spec.chains.find(m.rods[i].name);
    if (it == spec.chains.end())
      fail(spec, 0, fmt::format("mechanics.chains has no entry for rod '{}'", m.rods[i].name));
    m.chains[i] = build_chain(spec, m, i, it->second);
  }
}

// Quantities formed from several parameters.
void derive(const ModelSpec& spec, Model& m) {
  m.sensor_mount.enabled = !schema::group_instances(spec, Group::SensorMount).empty();
  double rod_mass_kg = 0.0;
  for (const auto& rod : m.rods) rod_mass_kg += rod.mass_kg;
  auto& n = m.thermal_network;
  n.rods_C_J_per_K = n.rod_specific_heat_J_per_kg_K * rod_mass_kg;
  // Eq. (21) products; rod_length_m = 0 (the default when [thermal_expansion] is absent):
  // the longest rod.
  const auto& te = m.thermal_expansion;
  double rod_length_m = te.rod_length_m;
  if (rod_length_m == 0.0)
    for (const auto& rod : m.rods) rod_length_m = std::max(rod_length_m, rod.length_m);
  m.xT_rod_m_per_K = m.material.alpha_thermal_per_K * rod_length_m;
  m.xT_magnetizer_m_per_K = te.magnetizer_alpha_per_K * te.magnetizer_length_m;
  m.xT_output_rod_m_per_K = te.output_rod_alpha_per_K * te.output_rod_length_m;
  m.xT_sleeve_m_per_K = te.sleeve_alpha_per_K * te.sleeve_length_m;
}

// Everything of compile() but the Model's copy of the spec and the validity check, which reads
// it (m.spec).
Model build_model(const ModelSpec& spec, const std::vector<std::string>& derived) {
  check_spec(spec, derived);
  Model m;
  m.options = spec.options;
  size_instances(spec, m);
  land_parameters(spec, m);
  m.preload_N = preload_force_N(spec);
  build_circuit(spec, m);
  build_flux_sensor(spec, m);
  build_chains(spec, m);
  derive(spec, m);
  return m;
}

}  // namespace

double preload_area_m2(const ModelSpec& spec) {
  if (spec.rods.empty()) fail(spec, 0, "stack.rods is empty: at least one rod is required");
  const std::string& rod = spec.rods.front();
  const double ro = spec.get(rod + ".outer_diameter_m") / 2.0;
  const double ri = spec.get(rod + ".inner_diameter_m") / 2.0;
  return std::numbers::pi * (ro * ro - ri * ri);
}

std::string preload_key(const ModelSpec& spec) {
  return spec.params.count("preload.prestress_MPa") ? "preload.prestress_MPa" : "preload.force_N";
}

double preload_force_N(const ModelSpec& spec) {
  const auto it = spec.params.find("preload.prestress_MPa");
  if (it == spec.params.end()) return spec.get("preload.force_N");
  if (spec.params.count("preload.force_N"))
    fail(spec, it->second.line,
         "[preload]: give preload.force_N or preload.prestress_MPa, not both (the force is "
         "derived from the prestress)");
  return it->second.value * 1e6 * preload_area_m2(spec);
}

Model compile(const ModelSpec& spec) { return compile(ModelSpec(spec)); }

Model compile(ModelSpec&& spec) {
  // gmasim/model/derived.hpp: what follows from the geometry (its inputs are checked).
  const std::vector<std::string> derived = apply_derivations(spec);
  Model m = build_model(spec, derived);
  m.spec = std::move(spec);
  check_model_validity(m);
  return m;
}

}  // namespace gmasim
