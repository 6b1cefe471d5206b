// Model files: the sections that hold structure (the rod list, the circuit netlist, the flux
// sensor, the mechanics and its load chains); their numbers go through the parameter table
// (read_group, model_loader.cpp).
#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <set>

#include "io/model_loader.hpp"
#include "io/schema.hpp"

namespace gmasim::io_detail {
namespace {

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

void ModelLoader::read_root(const toml::table& root) {
  read_stack(root);
  check_top_level(root);
  read_meta(root);
  read_options(root);
  read_group_table(root, Group::Reference, 1);
  read_group_table(root, Group::Material, 1);
  read_group_table(root, Group::Preload, 1);
  read_group_table(root, Group::Magnet, 1);
  read_rods(root);
  read_circuit(root);
  read_sensor(root);
  read_calibration(root);
  read_mechanics(root);
  read_group_table(root, Group::ThermalExpansion, 1);
  read_group_table(root, Group::ThermalNetwork, 1);
  read_group_table(root, Group::Validity, 1);
}

void ModelLoader::check_top_level(const toml::table& root) {
  std::vector<std::string> allowed;
  for (auto r : schema::reserved_tables()) allowed.emplace_back(r);
  if (rods_ok_) {
    for (const auto& r : spec_.rods) allowed.push_back(r);
    check_keys(root, "the top level", allowed);
    return;
  }
  // Without a valid rod list, tables cannot be told from typos: check plain keys.
  for (const auto& [key, node] : root) {
    if (node.is_table()) continue;
    problem(node_line(node), fmt::format("unknown key '{}' at the top level; expected "
                                         "one of: {}, and the rods' tables",
                                         key.str(), join(allowed, ", ")));
  }
}

void ModelLoader::read_stack(const toml::table& root) {
  const auto* t = table_at(root, "stack", "stack", 1);
  if (!t) return;
  check_keys(*t, "[stack]", {"rods"});
  const auto* node = required(*t, "rods", "stack", node_line(*t));
  if (!node) return;
  auto rods = string_array(*node, "stack.rods");
  if (!rods) return;
  const long line = node_line(*node);
  spec_.option_lines["stack.rods"] = line;
  bool ok = true;
  if (rods->empty()) {
    problem(line, "stack.rods: the list of rods is empty; at least one rod is needed");
    ok = false;
  }
  std::set<std::string> seen;
  const auto reserved = schema::reserved_tables();
  for (const auto& r : *rods) {
    if (!valid_name(r.name)) {
      problem(r.line, fmt::format("stack.rods: rod name '{}' must be non-empty and contain no '.'",
                                  r.name));
      ok = false;
    } else if (std::find(reserved.begin(), reserved.end(), r.name) != reserved.end()) {
      problem(r.line, fmt::format("stack.rods: rod name '{}' is a reserved table name", r.name));
      ok = false;
    } else if (!seen.insert(r.name).second) {
      problem(r.line, fmt::format("stack.rods: rod '{}' is listed twice", r.name));
      ok = false;
    }
  }
  if (!ok) return;
  for (const auto& r : *rods) spec_.rods.push_back(r.name);
  rods_ok_ = true;
}

void ModelLoader::read_rods(const toml::table& root) {
  const long stack_line =
      spec_.option_lines.count("stack.rods") ? spec_.option_lines.at("stack.rods") : 1;
  for (const auto& rod : spec_.rods) {
    const toml::node* node = root.get(rod);
    if (!node) {
      problem(stack_line, fmt::format("missing table [{}] (named in stack.rods)", rod));
      continue;
    }
    if (!node->is_table()) {
      problem(node_line(*node),
              fmt::format("[{}]: expected a table, got {}", rod, type_name(*node)));
      continue;
    }
    const auto& t = *node->as_table();
    // The table of the magnetisation law the options select ([<rod>.ja], [<rod>.preisach]).
    for (const auto& g : parameter_groups()) {
      if (!g.law || *g.law != spec_.options.magnetisation_law) continue;
      read_group(t, Group::Rod, rod, {std::string(g.path.substr(g.path.rfind('.') + 1))});
      read_group_table(t, g.group, node_line(t), rod);
    }
  }
}

// ---- circuit ------------------------------------------------------------------------------

void ModelLoader::read_circuit(const toml::table& root) {
  const auto* t = table_at(root, "circuit", "circuit", 1);
  if (!t) return;
  const long tl = node_line(*t);
  check_keys(*t, "[circuit]",
             {"reference_node", "nodes", "reluctances_per_H", "reluctance_geometry", "branches"});
  if (auto s = read_string(*t, "reference_node", "circuit")) {
    spec_.reference_node = *s;
    spec_.option_lines["circuit.reference_node"] = node_line(*t->get("reference_node"));
  }
  read_nodes(*t, tl);
  read_reluctance_geometry(*t, tl);
  const auto reluctances = read_reluctances(*t, tl);
  read_branches(*t, tl, reluctances);
}

// [circuit.reluctance_geometry.<name>] (optional): a fixed reluctance by its geometry, each a
// table of the ReluctanceGeometry rows; the reluctance itself is derived
// (gmasim/model/derived.hpp).
void ModelLoader::read_reluctance_geometry(const toml::table& circuit, long line) {
  if (!circuit.get("reluctance_geometry")) return;
  const std::string dotted = "circuit.reluctance_geometry";
  const auto* t = table_at(circuit, "reluctance_geometry", dotted, line);
  if (!t) return;
  for (const auto& [name, sub] : named_tables(*t, dotted)) {
    spec_.reluctance_geometry_names.push_back(name);
    read_group(*sub, Group::ReluctanceGeometry, dotted + "." + name);
  }
}

// [circuit.reluctances_per_H]: free names, each a number of the Reluctance row. The names,
// or nullopt if the table could not be read.
std::optional<std::vector<std::string>> ModelLoader::read_reluctances(const toml::table& circuit,
                                                                      long line) {
  // A reluctance given only by its geometry: its key, unset (line 0), for the derivation. The
  // table may then be absent.
  const auto& by_geometry = spec_.reluctance_geometry_names;
  std::vector<std::string> names;
  const toml::table empty;
  const toml::table* rt = &empty;
  if (circuit.get("reluctances_per_H") || by_geometry.empty())
    rt = table_at(circuit, "reluctances_per_H", "circuit.reluctances_per_H", line);
  if (!rt) return std::nullopt;
  for (const auto& name : by_geometry)
    if (!rt->get(name)) {
      names.push_back(name);
      spec_.params["circuit.reluctances_per_H." + name] =
          ParamValue{std::numeric_limits<double>::quiet_NaN(), "", 0, false};
    }
  for (const auto& [key, node] : *rt) {
    const std::string name(key.str());
    if (!valid_name(name)) {
      problem(node_line(node), fmt::format("[circuit.reluctances_per_H]: name '{}' must be "
                                           "non-empty and contain no '.'",
                                           name));
      continue;
    }
    names.push_back(name);
    store_number(node, "circuit.reluctances_per_H." + name);
  }
  return names;
}

void ModelLoader::read_branches(const toml::table& circuit, long circuit_line,
                                const std::optional<std::vector<std::string>>& reluctances) {
  const toml::node* bnode = required(circuit, "branches", "circuit", circuit_line);
  if (!bnode) return;
  const auto* arr = bnode->as_array();
  if (!arr || !arr->is_array_of_tables() || arr->empty()) {
    problem(node_line(*bnode), fmt::format("circuit.branches: expected a non-empty array of "
                                           "tables ([[circuit.branches]]), got {}",
                                           type_name(*bnode)));
    return;
  }
  std::vector<std::string> names;
  std::size_t index = 0;
  for (const auto& el : *arr) read_branch(*el.as_table(), ++index, names, reluctances);
}

// One [[circuit.branches]] entry: its name, ends, reluctance source and numbers.
void ModelLoader::read_branch(const toml::table& b, std::size_t index,
                              std::vector<std::string>& names,
                              const std::optional<std::vector<std::string>>& reluctances) {
  const long bl = node_line(b);
  const std::string where = fmt::format("circuit.branches[{}]", index);
  std::vector<std::string> keys = {"name", "from", "to", "series", "rod"};
  for (const auto& row : parameter_table())
    if (row.group == Group::Branch) keys.emplace_back(row.key);
  check_keys(b, "[[circuit.branches]] #" + std::to_string(index), keys);
  SpecBranch sb;
  sb.line = bl;
  auto name = read_string(b, "name", where);
  auto from = read_string(b, "from", where);
  auto to = read_string(b, "to", where);
  bool ok = name && from && to;
  if (name && !valid_name(*name)) {
    problem(bl,
            fmt::format("{}: branch name '{}' must be non-empty and contain no '.'", where, *name));
    name.reset();
  } else if (name && contains(names, *name)) {
    problem(node_line(*b.get("name")),
            fmt::format("{}: branch name '{}' is used twice", where, *name));
    name.reset();
  }
  if (name) names.push_back(*name);
  ok = ok && name;
  const std::string label = name ? fmt::format("circuit branch '{}'", *name) : where;
  for (auto [node_name, value] : {std::pair{"from", &from}, std::pair{"to", &to}}) {
    if (*value && value->value().empty()) {
      problem(node_line(*b.get(node_name)),
              fmt::format("{}: '{}' must name a node, got an empty string", label, node_name));
      ok = false;
    }
  }
  ok = read_branch_source(b, label, sb, reluctances) && ok;
  if (name) read_group(b, Group::Branch, "circuit.branches." + *name);
  if (!ok) return;
  sb.name = *name;
  sb.from = *from;
  sb.to = *to;
  spec_.branches.push_back(std::move(sb));
}

// A branch's reluctance: exactly one of `series` (named reluctances) or `rod`.
bool ModelLoader::read_branch_source(const toml::table& b, const std::string& label, SpecBranch& sb,
                                     const std::optional<std::vector<std::string>>& reluctances) {
  const toml::node* series = b.get("series");
  const toml::node* rod = b.get("rod");
  if ((series != nullptr) == (rod != nullptr)) {
    problem(node_line(b), fmt::format("{}: needs exactly one of 'series' (reluctance names) or "
                                      "'rod' (a rod of stack.rods)",
                                      label));
    return false;
  }
  if (rod) {
    auto r = string_of(*rod, label + ".rod");
    if (!r) return false;
    sb.rod = *r;
    if (rods_ok_ && !contains(spec_.rods, *r)) {
      problem(node_line(*rod), fmt::format("{}: rod = \"{}\" names an unknown rod; "
                                           "stack.rods has: {}",
                                           label, *r, join(spec_.rods, ", ")));
      return false;
    }
    return true;
  }
  auto list = string_array(*series, label + ".series");
  if (!list) return false;
  bool ok = true;
  if (list->empty()) {
    problem(node_line(*series), fmt::format("{}: 'series' is empty", label));
    ok = false;
  }
  for (const auto& r : *list) {
    if (reluctances && !contains(*reluctances, r.name)) {
      problem(r.line, fmt::format("{}: series names unknown reluctance '{}' (not in "
                                  "[circuit.reluctances_per_H])",
                                  label, r.name));
      ok = false;
    }
    sb.series.push_back(r.name);
  }
  return ok;
}

// circuit.nodes: the non-reference nodes, unique, none the reference node. Whether the
// branches' `from`/`to` name them is checked by compile().
void ModelLoader::read_nodes(const toml::table& circuit, long circuit_line) {
  const auto* node = required(circuit, "nodes", "circuit", circuit_line);
  if (!node) return;
  auto list = string_array(*node, "circuit.nodes");
  if (!list) return;
  spec_.nodes_line = node_line(*node);
  spec_.option_lines["circuit.nodes"] = spec_.nodes_line;
  if (list->empty())
    problem(spec_.nodes_line, "circuit.nodes: the list is empty; name at least one node");
  std::set<std::string> seen;
  for (const auto& n : *list) {
    if (n.name.empty()) {
      problem(n.line, "circuit.nodes: a node name is empty");
    } else if (n.name == spec_.reference_node) {
      problem(n.line, fmt::format("circuit.nodes: '{}' is the reference node "
                                  "(circuit.reference_node); list only the other nodes",
                                  n.name));
    } else if (!seen.insert(n.name).second) {
      problem(n.line, fmt::format("circuit.nodes: node '{}' is listed twice", n.name));
    }
    spec_.nodes.push_back(n.name);
  }
}

void ModelLoader::read_sensor(const toml::table& root) {
  const auto* t = table_at(root, "sensor", "sensor", 1);
  if (!t) return;
  check_keys(*t, "[sensor]", {"flux_branches"});
  const auto* node = required(*t, "flux_branches", "sensor", node_line(*t));
  if (!node) return;
  auto list = string_array(*node, "sensor.flux_branches");
  if (!list) return;
  spec_.option_lines["sensor.flux_branches"] = node_line(*node);
  if (list->empty())
    problem(node_line(*node),
            "sensor.flux_branches: the list is empty; name at least one "
            "branch of [[circuit.branches]]");
  const toml::node* branches = root.at_path("circuit.branches").node();
  for (const auto& b : *list) {
    const bool known = std::any_of(spec_.branches.begin(), spec_.branches.end(),
                                   [&](const SpecBranch& sb) { return sb.name == b.name; });
    // Only report when the branch list itself was read (else that problem explains it).
    if (!known && branches && branches->is_array() &&
        spec_.branches.size() == branches->as_array()->size())
      problem(b.line, fmt::format("sensor.flux_branches: unknown branch '{}' (not a name in "
                                  "[[circuit.branches]])",
                                  b.name));
    spec_.flux_sensor_branches.push_back(b.name);
  }
}

// ---- calibration ----------------------------------------------------------------------

// Optional: the claims (data/claims.toml ids) the model was fitted to; `gmasim reproduce`
// counts every other claim as a prediction. Written by `gmasim identify` (its fit spec's claim
// targets and [[by_construction]] claims); the ids are checked against the claims when scored.
void ModelLoader::read_calibration(const toml::table& root) {
  if (!root.get("calibration")) return;  // optional: an uncalibrated model predicts every claim
  const auto* t = table_at(root, "calibration", "calibration", 1);
  if (!t) return;
  check_keys(*t, "[calibration]", {"fitted_claims"});
  const auto* node = required(*t, "fitted_claims", "calibration", node_line(*t));
  if (!node) return;
  auto list = string_array(*node, "calibration.fitted_claims");
  if (!list) return;
  spec_.option_lines["calibration.fitted_claims"] = node_line(*node);
  std::set<std::string> seen;
  for (const auto& c : *list) {
    if (!seen.insert(c.name).second)
      problem(c.line, fmt::format("calibration.fitted_claims: claim '{}' is listed twice", c.name));
    spec_.fitted_claims.push_back(c.name);
  }
}

// ---- mechanics ----------------------------------------------------------------------------

void ModelLoader::read_mechanics(const toml::table& root) {
  const auto* t = table_at(root, "mechanics", "mechanics", 1);
  if (!t) return;
  const long tl = node_line(*t);
  if (const auto* old = t->get("output_stage"))
    problem(node_line(*old),
            "[mechanics.output_stage] is gone: the 1270 Hz body is the displacement sensor's "
            "mount, [mechanics.sensor_mount] (mass_kg, stiffness_N_per_m, damping_N_s_per_m, "
            "actuator_mass_kg; docs/model.md, \"The sensor mount\")");
  check_keys(*t, "[mechanics]",
             {"elements", "sleeve_modulus", "sleeves", "chains", "sensor_mount", "output_stage"});
  // Optional: absent means the sensor reads the stack output.
  read_group_table(*t, Group::SensorMount, tl);
  bool members_ok = rods_ok_;
  members_ok = read_members(*t, tl, "elements", Group::Element, spec_.element_names) && members_ok;
  read_group_table(*t, Group::SleeveModulus, tl);
  // [mechanics.sleeves] is optional: a stack without sleeves (a single rod) has none.
  if (t->get("sleeves"))
    members_ok = read_members(*t, tl, "sleeves", Group::Sleeve, spec_.sleeve_names) && members_ok;
  read_chains(*t, tl, members_ok);
}

// The named members of [mechanics.<key>] (elements or sleeves), each a table of group `g`.
// False if a member could not be read (the chains then cannot tell a typo).
bool ModelLoader::read_members(const toml::table& mech, long mech_line, std::string_view key,
                               Group g, std::vector<std::string>& names) {
  const std::string dotted = "mechanics." + std::string(key);
  const auto* t = table_at(mech, key, dotted, mech_line);
  if (!t) return false;
  const auto subs = named_tables(*t, dotted);
  for (const auto& [name, sub] : subs) {
    const bool is_element = contains(spec_.element_names, name);
    if (contains(spec_.rods, name) || is_element) {
      problem(node_line(*sub),
              fmt::format("[{}.{}]: the name is also {}; chain names must be unique", dotted, name,
                          is_element ? "a mechanics element" : "a rod of stack.rods"));
    }
    names.push_back(name);
    read_group(*sub, g, dotted + "." + name);
  }
  return t->size() == subs.size();
}

void ModelLoader::read_chains(const toml::table& mech, long mech_line, bool members_ok) {
  const auto* t = table_at(mech, "chains", "mechanics.chains", mech_line);
  if (!t || !rods_ok_) return;
  const long tl = node_line(*t);
  check_keys(*t, "[mechanics.chains]", spec_.rods);
  for (const auto& rod : spec_.rods) {
    const auto* node = t->get(rod);
    if (!node) {
      problem(tl, fmt::format("missing key '{}' in [mechanics.chains]: every rod of "
                              "stack.rods needs a load chain",
                              rod));
      continue;
    }
    const std::string dotted = "mechanics.chains." + rod;
    auto list = string_array(*node, dotted);
    if (!list) continue;
    spec_.option_lines[dotted] = node_line(*node);
    std::vector<std::string> chain;
    for (const auto& m : *list) {
      if (m.name == rod) {
        problem(m.line, fmt::format("{}: rod '{}' cannot be in its own load chain", dotted, rod));
      } else if (contains(chain, m.name)) {
        problem(m.line, fmt::format("{}: '{}' appears twice", dotted, m.name));
      } else if (members_ok && !contains(spec_.element_names, m.name) &&
                 !contains(spec_.sleeve_names, m.name) && !contains(spec_.rods, m.name)) {
        problem(m.line, fmt::format("{}: unknown member '{}' (not a [mechanics.elements.*], "
                                    "[mechanics.sleeves.*] or a rod of stack.rods)",
                                    dotted, m.name));
      }
      chain.push_back(m.name);
    }
    spec_.chains[rod] = std::move(chain);
  }
}

}  // namespace gmasim::io_detail
