// Model files: TOML -> ModelSpec, validated field by field against the schema
// (model/schema.cpp); the parameter table of `model show`.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

#include "common/text_io.hpp"
#include "common/toml_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io.hpp"
#include "io/schema.hpp"

namespace gmasim {

// =======================================================================================
// Schema text helpers (the schema itself: model/schema.cpp)
// =======================================================================================
namespace schema {

std::string trailing_comment(std::string_view line) {
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    const char c = line[i];
    if (c == '#') {
      std::string_view rest = line.substr(i + 1);
      const auto b = rest.find_first_not_of(" \t");
      if (b == std::string_view::npos) return "";
      const auto e = rest.find_last_not_of(" \t\r");
      return std::string(rest.substr(b, e - b + 1));
    }
    if (c == '"' || c == '\'') {
      const std::string triple(3, c);
      if (line.substr(i, 3) == triple) {
        const auto close = line.find(triple, i + 3);
        if (close == std::string_view::npos) return "";  // multi-line string continues
        i = close + 3;
        continue;
      }
      ++i;
      while (i < n && line[i] != c) {
        if (c == '"' && line[i] == '\\') ++i;  // escape in a basic string
        ++i;
      }
      ++i;  // closing quote
      continue;
    }
    ++i;
  }
  return "";
}

}  // namespace schema

// =======================================================================================
// Loader
// =======================================================================================
namespace {

using schema::Field;

std::string join(const std::vector<std::string>& items, std::string_view sep) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += sep;
    out += items[i];
  }
  return out;
}

std::string_view type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a float";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    default:
      return "nothing";
  }
}

long node_line(const toml::node& n) {
  const auto l = static_cast<long>(n.source().begin.line);
  return l > 0 ? l : 1;
}

bool valid_name(const std::string& name) {
  return !name.empty() && name.find('.') == std::string::npos;
}

struct NamedLine {
  std::string name;
  long line;
};

class Loader {
 public:
  Loader(std::string_view text, const std::string& source)
      : text_(text), lines_(io_detail::split_lines(text, io_detail::StripCR::Yes)) {
    spec_.source = source;
  }

  ModelSpec run() {
    const toml::table root = io_detail::parse_toml(text_, spec_.source);
    read_root(root);
    for (const auto& [name, pv] : spec_.params)
      if (auto p = schema::check_value(spec_, name, pv.value)) problem(pv.line, *p);
    if (!problems_.empty()) {
      std::stable_sort(problems_.begin(), problems_.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      std::string msg;
      for (std::size_t i = 0; i < problems_.size(); ++i) {
        if (i > 0) msg += '\n';
        msg += located(spec_.source, problems_[i].first, problems_[i].second);
      }
      throw InputError(msg);
    }
    return std::move(spec_);
  }

 private:
  std::string_view text_;
  std::vector<std::string_view> lines_;
  ModelSpec spec_;
  std::vector<std::pair<long, std::string>> problems_;
  bool rods_ok_ = false;

  void problem(long line, std::string msg) { problems_.emplace_back(line, std::move(msg)); }

  std::string comment_at(long line) const {
    if (line < 1 || line > static_cast<long>(lines_.size())) return "";
    return schema::trailing_comment(lines_[static_cast<std::size_t>(line - 1)]);
  }

  // The trailing comment of a value: on its last line (multi-line arrays), else its first.
  std::string comment_of(const toml::node& n) const {
    const auto& src = n.source();
    std::string c = comment_at(static_cast<long>(src.end.line));
    if (c.empty() && src.end.line != src.begin.line) c = comment_at(node_line(n));
    return c;
  }

  // ---- generic readers ---------------------------------------------------------------

  // A sub-table; reports a missing table at `missing_line`.
  const toml::table* table_at(const toml::table& parent, std::string_view key,
                              const std::string& dotted, long missing_line) {
    const toml::node* node = parent.get(key);
    if (!node) {
      problem(missing_line, fmt::format("missing table [{}]", dotted));
      return nullptr;
    }
    if (!node->is_table()) {
      problem(node_line(*node),
              fmt::format("[{}]: expected a table, got {}", dotted, type_name(*node)));
      return nullptr;
    }
    return node->as_table();
  }

  void check_keys(const toml::table& t, const std::string& where,
                  const std::vector<std::string>& allowed) {
    for (const auto& [key, node] : t) {
      const std::string k(key.str());
      if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) continue;
      const long kl = static_cast<long>(key.source().begin.line);
      problem(kl > 0 ? kl : node_line(node),
              fmt::format("unknown key '{}' {} {}; expected one of: {}", k,
                          where.starts_with('[') ? "in" : "at", where, join(allowed, ", ")));
    }
  }

  static std::vector<std::string> keys_of(std::span<const Field> fields,
                                          std::initializer_list<std::string_view> extra = {}) {
    std::vector<std::string> keys;
    for (const auto& f : fields) keys.emplace_back(f.key);
    for (auto e : extra) keys.emplace_back(e);
    return keys;
  }

  const toml::node* required(const toml::table& t, std::string_view key,
                             const std::string& table_name, long table_line) {
    const toml::node* node = t.get(key);
    if (!node) problem(table_line, fmt::format("missing key '{}' in [{}]", key, table_name));
    return node;
  }

  void store_number(const toml::node& node, const std::string& dotted, const Field& f) {
    if (!node.is_integer() && !node.is_floating_point()) {
      problem(node_line(node),
              fmt::format("{}: expected a number, got {}", dotted, type_name(node)));
      return;
    }
    ParamValue pv;
    pv.value = node.value<double>().value_or(std::numeric_limits<double>::quiet_NaN());
    pv.unit = schema::unit_of(f);
    pv.provenance = comment_of(node);
    pv.line = node_line(node);
    spec_.params[dotted] = std::move(pv);
  }

  // Reads every field of `fields` from table `t` named `table_name` (also the prefix of
  // the dotted names); `extra` are further allowed keys (sub-tables) read elsewhere.
  void read_fields(const toml::table& t, const std::string& table_name,
                   std::span<const Field> fields,
                   std::initializer_list<std::string_view> extra = {}) {
    const long tl = node_line(t);
    check_keys(t, "[" + table_name + "]", keys_of(fields, extra));
    for (const auto& f : fields)
      if (const auto* node = required(t, f.key, table_name, tl))
        store_number(*node, table_name + "." + std::string(f.key), f);
  }

  void read_table_fields(const toml::table& parent, std::string_view key, const std::string& dotted,
                         long missing_line, std::span<const Field> fields) {
    if (const auto* t = table_at(parent, key, dotted, missing_line))
      read_fields(*t, dotted, fields);
  }

  std::optional<std::string> string_of(const toml::node& node, const std::string& dotted) {
    if (!node.is_string()) {
      problem(node_line(node),
              fmt::format("{}: expected a string, got {}", dotted, type_name(node)));
      return std::nullopt;
    }
    return std::string(node.as_string()->get());
  }

  std::optional<std::string> read_string(const toml::table& t, std::string_view key,
                                         const std::string& table_name) {
    const auto* node = required(t, key, table_name, node_line(t));
    if (!node) return std::nullopt;
    return string_of(*node, table_name + "." + std::string(key));
  }

  std::optional<std::vector<NamedLine>> string_array(const toml::node& node,
                                                     const std::string& dotted) {
    const auto* arr = node.as_array();
    if (!arr) {
      problem(node_line(node),
              fmt::format("{}: expected an array of strings, got {}", dotted, type_name(node)));
      return std::nullopt;
    }
    std::vector<NamedLine> out;
    bool ok = true;
    for (const auto& el : *arr) {
      if (!el.is_string()) {
        problem(node_line(el),
                fmt::format("{}: expected an array of strings, found {}", dotted, type_name(el)));
        ok = false;
        continue;
      }
      out.push_back({std::string(el.as_string()->get()), node_line(el)});
    }
    if (!ok) return std::nullopt;
    return out;
  }

  // Sub-tables of `t` in file order, each checked to be a table with a valid name.
  std::vector<std::pair<std::string, const toml::table*>> named_tables(const toml::table& t,
                                                                       const std::string& dotted) {
    std::vector<std::pair<std::string, const toml::table*>> out;
    for (const auto& [key, node] : t) {
      const std::string name(key.str());
      if (!node.is_table()) {
        problem(node_line(node),
                fmt::format("{}.{}: expected a table, got {}", dotted, name, type_name(node)));
        continue;
      }
      if (!valid_name(name)) {
        problem(node_line(node), fmt::format("[{}]: name '{}' must be non-empty and contain no "
                                             "'.'",
                                             dotted, name));
        continue;
      }
      out.emplace_back(name, node.as_table());
    }
    std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
      return node_line(*a.second) < node_line(*b.second);
    });
    return out;
  }

  // ---- sections ----------------------------------------------------------------------

  void read_root(const toml::table& root) {
    read_stack(root);
    {
      std::vector<std::string> allowed;
      for (auto r : schema::reserved_tables()) allowed.emplace_back(r);
      if (rods_ok_) {
        for (const auto& r : spec_.rods) allowed.push_back(r);
        check_keys(root, "the top level", allowed);
      } else {
        // Without a valid rod list, tables cannot be told from typos: check plain keys.
        for (const auto& [key, node] : root) {
          if (node.is_table()) continue;
          problem(node_line(node), fmt::format("unknown key '{}' at the top level; expected "
                                               "one of: {}, and the rods' tables",
                                               key.str(), join(allowed, ", ")));
        }
      }
    }
    read_meta(root);
    read_options(root);
    read_table_fields(root, "reference", "reference", 1, schema::reference_fields());
    read_table_fields(root, "material", "material", 1, schema::material_fields());
    read_table_fields(root, "preload", "preload", 1, schema::preload_fields());
    read_defaulted(root, "magnet", "magnet", schema::magnet_defaults());
    read_rods(root);
    read_circuit(root);
    read_sensor(root);
    read_mechanics(root);
    read_defaulted(root, "thermal_expansion", "thermal_expansion",
                   schema::thermal_expansion_defaults());
    read_defaulted(root, "thermal_network", "thermal_network", schema::thermal_network_defaults());
  }

  // An optional table whose every key has a default (schema::DefaultedField): a key or the
  // whole table may be absent; a defaulted value is stored with line 0 and its provenance.
  void read_defaulted(const toml::table& parent, std::string_view key, const std::string& dotted,
                      std::span<const schema::DefaultedField> defaults) {
    const toml::table* t = nullptr;
    if (const toml::node* n = parent.get(key)) {
      t = table_at(parent, key, dotted, 1);
      if (t == nullptr) return;
      spec_.option_lines["[" + dotted + "]"] = node_line(*n);
      std::vector<std::string> keys;
      for (const auto& d : defaults) keys.emplace_back(d.field.key);
      check_keys(*t, "[" + dotted + "]", keys);
    }
    for (const auto& d : defaults) {
      const std::string name = dotted + "." + std::string(d.field.key);
      if (t != nullptr) {
        if (const toml::node* node = t->get(d.field.key)) {
          store_number(*node, name, d.field);
          continue;
        }
      }
      ParamValue pv;
      pv.value = d.value;
      pv.unit = schema::unit_of(d.field);
      pv.provenance = std::string(d.provenance);
      pv.line = 0;
      spec_.params[name] = std::move(pv);
    }
  }

  void read_meta(const toml::table& root) {
    const auto* t = table_at(root, "meta", "meta", 1);
    if (!t) return;
    check_keys(*t, "[meta]", {"name", "description"});
    for (std::string_view key : {"name", "description"}) {
      if (auto s = read_string(*t, key, "meta")) {
        const std::string dotted = "meta." + std::string(key);
        spec_.options[dotted] = *s;
        spec_.option_lines[dotted] = node_line(*t->get(key));
      }
    }
  }

  void read_options(const toml::table& root) {
    const auto* t = table_at(root, "options", "options", 1);
    if (!t) return;
    struct Choice {
      std::string_view key;
      std::vector<std::string> values;  // empty: a boolean
    };
    const std::vector<Choice> choices = {
        {"stress_sign", {"compression_negative", "compression_positive"}},
        {"eq10_temperature_scale", {"room_referenced", "kelvin", "celsius"}},
        {"eq10_shape_law", {"printed", "mean_field"}},
        {"magnetic_state", {"printed", "consistent"}},
        {"eq11_saturation", {"temperature", "reference"}},
        {"thermal_expansion_in_output", {}},
        {"geometry_thermal_expansion", {}},
    };
    std::vector<std::string> keys;
    for (const auto& c : choices) keys.emplace_back(c.key);
    check_keys(*t, "[options]", keys);
    const long tl = node_line(*t);
    for (const auto& c : choices) {
      const auto* node = required(*t, c.key, "options", tl);
      if (!node) continue;
      const std::string dotted = "options." + std::string(c.key);
      std::string value;
      if (c.values.empty()) {
        if (!node->is_boolean()) {
          problem(node_line(*node), fmt::format("{}: expected a boolean (true or false), got {}",
                                                dotted, type_name(*node)));
          continue;
        }
        value = node->as_boolean()->get() ? "true" : "false";
      } else {
        auto s = string_of(*node, dotted);
        if (!s) continue;
        if (std::find(c.values.begin(), c.values.end(), *s) == c.values.end()) {
          problem(node_line(*node),
                  fmt::format("{} = \"{}\": must be one of: {}", dotted, *s, join(c.values, ", ")));
          continue;
        }
        value = *s;
      }
      spec_.options[dotted] = value;
      spec_.option_lines[dotted] = node_line(*node);
    }
  }

  void read_stack(const toml::table& root) {
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
        problem(r.line, fmt::format("stack.rods: rod name '{}' must be non-empty and contain "
                                    "no '.'",
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

  void read_rods(const toml::table& root) {
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
      read_fields(t, rod, schema::rod_fields(), {"ja"});
      read_table_fields(t, "ja", rod + ".ja", node_line(t), schema::ja_fields());
    }
  }

  void read_circuit(const toml::table& root) {
    const auto* t = table_at(root, "circuit", "circuit", 1);
    if (!t) return;
    const long tl = node_line(*t);
    check_keys(*t, "[circuit]", {"reference_node", "nodes", "reluctances_per_H", "branches"});
    if (auto s = read_string(*t, "reference_node", "circuit")) {
      spec_.reference_node = *s;
      spec_.option_lines["circuit.reference_node"] = node_line(*t->get("reference_node"));
    }
    read_nodes(*t, tl);
    std::set<std::string> reluctances;
    bool reluctances_ok = false;
    if (const auto* rt = table_at(*t, "reluctances_per_H", "circuit.reluctances_per_H", tl)) {
      reluctances_ok = true;
      for (const auto& [key, node] : *rt) {
        const std::string name(key.str());
        if (!valid_name(name)) {
          problem(node_line(node), fmt::format("[circuit.reluctances_per_H]: name '{}' must be "
                                               "non-empty and contain no '.'",
                                               name));
          continue;
        }
        reluctances.insert(name);
        store_number(node, "circuit.reluctances_per_H." + name, schema::kReluctanceField);
      }
    }
    const toml::node* bnode = required(*t, "branches", "circuit", tl);
    if (!bnode) return;
    const auto* arr = bnode->as_array();
    if (!arr || !arr->is_array_of_tables() || arr->empty()) {
      problem(node_line(*bnode), fmt::format("circuit.branches: expected a non-empty array of "
                                             "tables ([[circuit.branches]]), got {}",
                                             type_name(*bnode)));
      return;
    }
    std::set<std::string> names;
    std::size_t index = 0;
    for (const auto& el : *arr) {
      ++index;
      const auto& b = *el.as_table();
      const long bl = node_line(b);
      const std::string where = fmt::format("circuit.branches[{}]", index);
      std::vector<std::string> keys = {"name", "from", "to", "series", "rod"};
      for (const auto& f : schema::branch_number_fields()) keys.emplace_back(f.key);
      check_keys(b, "[[circuit.branches]] #" + std::to_string(index), keys);
      SpecBranch sb;
      sb.line = bl;
      bool ok = true;
      auto name = read_string(b, "name", where);
      auto from = read_string(b, "from", where);
      auto to = read_string(b, "to", where);
      if (!name || !from || !to) ok = false;
      if (name) {
        if (!valid_name(*name)) {
          problem(bl, fmt::format("{}: branch name '{}' must be non-empty and contain no '.'",
                                  where, *name));
          ok = false;
          name.reset();
        } else if (!names.insert(*name).second) {
          problem(node_line(*b.get("name")),
                  fmt::format("{}: branch name '{}' is used twice", where, *name));
          ok = false;
          name.reset();
        }
      }
      const std::string label = name ? fmt::format("circuit branch '{}'", *name) : where;
      for (auto [node_name, value] : {std::pair{"from", &from}, std::pair{"to", &to}}) {
        if (*value && value->value().empty()) {
          problem(node_line(*b.get(node_name)),
                  fmt::format("{}: '{}' must name a node, got an empty string", label, node_name));
          ok = false;
        }
      }
      const toml::node* series = b.get("series");
      const toml::node* rod = b.get("rod");
      if ((series != nullptr) == (rod != nullptr)) {
        problem(bl, fmt::format("{}: needs exactly one of 'series' (reluctance names) or "
                                "'rod' (a rod of stack.rods)",
                                label));
        ok = false;
      } else if (series) {
        if (auto list = string_array(*series, label + ".series")) {
          if (list->empty()) {
            problem(node_line(*series), fmt::format("{}: 'series' is empty", label));
            ok = false;
          }
          for (const auto& r : *list) {
            if (reluctances_ok && !reluctances.count(r.name)) {
              problem(r.line, fmt::format("{}: series names unknown reluctance '{}' (not in "
                                          "[circuit.reluctances_per_H])",
                                          label, r.name));
              ok = false;
            }
            sb.series.push_back(r.name);
          }
        } else {
          ok = false;
        }
      } else if (auto r = string_of(*rod, label + ".rod")) {
        if (rods_ok_ && std::find(spec_.rods.begin(), spec_.rods.end(), *r) == spec_.rods.end()) {
          problem(node_line(*rod), fmt::format("{}: rod = \"{}\" names an unknown rod; "
                                               "stack.rods has: {}",
                                               label, *r, join(spec_.rods, ", ")));
          ok = false;
        }
        sb.rod = *r;
      } else {
        ok = false;
      }
      if (name) {
        for (const auto& f : schema::branch_number_fields())
          if (const auto* n = b.get(f.key))
            store_number(*n, "circuit.branches." + *name + "." + std::string(f.key), f);
      }
      if (ok) {
        sb.name = *name;
        sb.from = *from;
        sb.to = *to;
        spec_.branches.push_back(std::move(sb));
      }
    }
  }

  // circuit.nodes: the non-reference nodes, unique, none the reference node. Whether the
  // branches' `from`/`to` name them is checked by compile().
  void read_nodes(const toml::table& circuit, long circuit_line) {
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

  void read_sensor(const toml::table& root) {
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

  void read_mechanics(const toml::table& root) {
    const auto* t = table_at(root, "mechanics", "mechanics", 1);
    if (!t) return;
    const long tl = node_line(*t);
    check_keys(*t, "[mechanics]",
               {"elements", "sleeve_modulus", "sleeves", "chains", "output_stage"});
    if (t->get("output_stage"))  // optional: absent means the sensor reads the stack output
      read_table_fields(*t, "output_stage", "mechanics.output_stage", tl,
                        schema::output_stage_fields());
    std::set<std::string> rods(spec_.rods.begin(), spec_.rods.end());
    bool members_ok = rods_ok_;
    if (const auto* et = table_at(*t, "elements", "mechanics.elements", tl)) {
      const auto subs = named_tables(*et, "mechanics.elements");
      if (et->size() != subs.size()) members_ok = false;
      for (const auto& [name, sub] : subs) {
        if (rods.count(name)) {
          problem(node_line(*sub), fmt::format("[mechanics.elements.{}]: the name is also a "
                                               "rod of stack.rods; chain names must be unique",
                                               name));
        }
        spec_.element_names.push_back(name);
        read_fields(*sub, "mechanics.elements." + name, schema::element_fields());
      }
    } else {
      members_ok = false;
    }
    read_defaulted(*t, "sleeve_modulus", "mechanics.sleeve_modulus",
                   schema::sleeve_modulus_defaults());
    // [mechanics.sleeves] is optional: a stack without sleeves (a single rod) has none.
    if (!t->get("sleeves")) {
    } else if (const auto* st = table_at(*t, "sleeves", "mechanics.sleeves", tl)) {
      const auto subs = named_tables(*st, "mechanics.sleeves");
      if (st->size() != subs.size()) members_ok = false;
      for (const auto& [name, sub] : subs) {
        const bool is_element = std::find(spec_.element_names.begin(), spec_.element_names.end(),
                                          name) != spec_.element_names.end();
        if (rods.count(name) || is_element) {
          problem(node_line(*sub),
                  fmt::format("[mechanics.sleeves.{}]: the name is also {}; "
                              "chain names must be unique",
                              name, is_element ? "a mechanics element" : "a rod of stack.rods"));
        }
        spec_.sleeve_names.push_back(name);
        read_fields(*sub, "mechanics.sleeves." + name, schema::sleeve_fields());
      }
    } else {
      members_ok = false;
    }
    read_chains(*t, tl, members_ok);
  }

  void read_chains(const toml::table& mech, long mech_line, bool members_ok) {
    const auto* t = table_at(mech, "chains", "mechanics.chains", mech_line);
    if (!t || !rods_ok_) return;
    const long tl = node_line(*t);
    check_keys(*t, "[mechanics.chains]", spec_.rods);
    auto contains = [](const std::vector<std::string>& v, const std::string& s) {
      return std::find(v.begin(), v.end(), s) != v.end();
    };
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
};

using io_detail::read_text_file;

std::string builtin_source_name() { return std::string(kBuiltinModelName) + " (built-in)"; }

// The model text behind spec.source, for the comments of options and structure rows; empty
// if it cannot be read (e.g. a spec parsed from a string).
std::string source_text(const std::string& source) {
  if (source == builtin_source_name()) return kBuiltinModelToml;
  try {
    return read_text_file(source, "model file");
  } catch (const InputError&) {
    return {};  // describe_model shows empty provenance for these rows
  }
}

}  // namespace

ModelSpec parse_model_spec(const std::string& toml_text, const std::string& source_name) {
  ModelSpec spec = Loader(toml_text, source_name).run();
  spec.text = toml_text;
  return spec;
}

ModelSpec load_model_spec(const std::string& path) {
  const std::string text = read_text_file(path, "model file");
  return parse_model_spec(text, path);
}

ModelSpec builtin_model_spec() {
  return parse_model_spec(kBuiltinModelToml, builtin_source_name());
}

Model load_model(const std::string& path) {
  return compile(path.empty() ? builtin_model_spec() : load_model_spec(path));
}

// =======================================================================================
// describe_model
// =======================================================================================
std::vector<ParamRow> describe_model(const ModelSpec& spec) {
  const std::string text = source_text(spec.source);
  const auto lines = io_detail::split_lines(text, io_detail::StripCR::Yes);
  auto comment_at = [&](long line) -> std::string {
    if (line < 1 || line > static_cast<long>(lines.size())) return "";
    return schema::trailing_comment(lines[static_cast<std::size_t>(line - 1)]);
  };
  auto line_of = [&](const std::string& key) -> long {
    const auto it = spec.option_lines.find(key);
    return it == spec.option_lines.end() ? 0 : it->second;
  };
  // A branch's comment: on its [[circuit.branches]] line, else on its `name =` line.
  auto branch_comment = [&](long header) -> std::string {
    std::string c = comment_at(header);
    if (!c.empty() || header < 1) return c;
    for (auto i = static_cast<std::size_t>(header); i < lines.size(); ++i) {
      std::string_view l = lines[i];
      const auto b = l.find_first_not_of(" \t");
      if (b == std::string_view::npos) continue;
      l.remove_prefix(b);
      if (l.starts_with('[')) break;
      if (l.starts_with("name")) {
        const auto e = l.find_first_not_of(" \t", 4);
        if (e != std::string_view::npos && l[e] == '=') return comment_at(static_cast<long>(i) + 1);
      }
    }
    return "";
  };

  std::vector<ParamRow> rows;
  for (const auto& [name, pv] : spec.params)
    rows.push_back({name, fmt::format("{:g}", pv.value), pv.unit, pv.provenance, pv.line});
  for (const auto& [name, value] : spec.options) {
    const long line = line_of(name);
    rows.push_back(
        {name, value, name.starts_with("meta.") ? "text" : "option", comment_at(line), line});
  }
  auto add_structure = [&](const std::string& name, std::string value, std::string unit,
                           long line) {
    rows.push_back({name, std::move(value), std::move(unit), comment_at(line), line});
  };
  add_structure("stack.rods", join(spec.rods, ", "), "rods", line_of("stack.rods"));
  if (!spec.reference_node.empty()) {
    add_structure("circuit.reference_node", spec.reference_node, "node",
                  line_of("circuit.reference_node"));
  }
  if (!spec.nodes.empty())
    add_structure("circuit.nodes", join(spec.nodes, ", "), "nodes", spec.nodes_line);
  for (const auto& b : spec.branches) {
    std::string value = fmt::format("{} -> {}: ", b.from, b.to);
    value += b.rod.empty() ? join(b.series, " + ") : "rod " + b.rod;
    rows.push_back({"circuit.branches." + b.name, value, "branch", branch_comment(b.line), b.line});
  }
  add_structure("sensor.flux_branches", join(spec.flux_sensor_branches, ", "), "branches",
                line_of("sensor.flux_branches"));
  for (const auto& rod : spec.rods) {
    const auto it = spec.chains.find(rod);
    if (it == spec.chains.end()) continue;
    add_structure("mechanics.chains." + rod, join(it->second, ", "), "chain",
                  line_of("mechanics.chains." + rod));
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const ParamRow& a, const ParamRow& b) { return a.line < b.line; });
  return rows;
}

}  // namespace gmasim
