// Model files: TOML -> ModelSpec. This file holds the generic readers, the reading of the
// numbers and options by the parameter table (gmasim/model/parameters.hpp) and the public entry
// points; the structure sections are in model_structure.cpp, `model show` in
// model_describe.cpp.
#include "io/model_loader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/text_io.hpp"
#include "common/toml_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/derived.hpp"
#include "io/schema.hpp"

namespace gmasim {
namespace io_detail {

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

std::string builtin_source_name() { return std::string(kBuiltinModelName) + " (built-in)"; }

bool valid_name(const std::string& name) {
  return !name.empty() && name.find('.') == std::string::npos;
}

// =======================================================================================
// The loader: generic readers
// =======================================================================================
ModelLoader::ModelLoader(std::string_view text, const std::string& source)
    : text_(text), lines_(split_lines(text, StripCR::Yes)) {
  spec_.source = source;
}

ModelSpec ModelLoader::run() {
  const toml::table root = parse_toml(text_, spec_.source);
  read_root(root);
  const std::vector<std::string> derived = apply_derivations(spec_);  // gmasim/model/derived.hpp
  for (const auto& [name, pv] : spec_.params) {
    if (std::find(derived.begin(), derived.end(), name) != derived.end()) continue;
    if (auto p = schema::check_value(spec_, name, pv.value)) problem(pv.line, *p);
  }
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

std::string ModelLoader::comment_at(long line) const {
  if (line < 1 || line > static_cast<long>(lines_.size())) return "";
  return schema::trailing_comment(lines_[static_cast<std::size_t>(line - 1)]);
}

// The trailing comment of a value: on its last line (multi-line arrays), else its first.
std::string ModelLoader::comment_of(const toml::node& n) const {
  const auto& src = n.source();
  std::string c = comment_at(static_cast<long>(src.end.line));
  if (c.empty() && src.end.line != src.begin.line) c = comment_at(node_line(n));
  return c;
}

// A sub-table; reports a missing table at `missing_line`.
const toml::table* ModelLoader::table_at(const toml::table& parent, std::string_view key,
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

void ModelLoader::check_keys(const toml::table& t, const std::string& where,
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

const toml::node* ModelLoader::required(const toml::table& t, std::string_view key,
                                        const std::string& table_name, long table_line) {
  const toml::node* node = t.get(key);
  if (!node) problem(table_line, fmt::format("missing key '{}' in [{}]", key, table_name));
  return node;
}

void ModelLoader::store_number(const toml::node& node, const std::string& dotted) {
  if (!node.is_integer() && !node.is_floating_point()) {
    problem(node_line(node), fmt::format("{}: expected a number, got {}", dotted, type_name(node)));
    return;
  }
  // toml++ gives no double for an integer beyond 2^53 (value<double>() is empty), and the NaN
  // that stood for it was reported as "NaN is not allowed": quote the integer instead
  if (node.is_integer() && !node.value<double>()) {
    problem(node_line(node),
            fmt::format("{} = {}: an integer beyond 2^53 (9007199254740992) is not exactly a "
                        "number here; give a smaller value",
                        dotted, node.as_integer()->get()));
    return;
  }
  ParamValue pv;
  pv.value = node.value<double>().value_or(std::numeric_limits<double>::quiet_NaN());
  pv.provenance = comment_of(node);
  pv.line = node_line(node);
  spec_.params[dotted] = std::move(pv);
}

// A key the file leaves out: the row's default, with line 0 and the row's provenance.
void ModelLoader::store_default(const std::string& dotted, const ParamDef& row) {
  ParamValue pv;
  pv.value = *row.default_value;
  pv.provenance = std::string(row.default_provenance);
  pv.line = 0;
  spec_.params[dotted] = std::move(pv);
}

std::optional<std::string> ModelLoader::string_of(const toml::node& node,
                                                  const std::string& dotted) {
  if (!node.is_string()) {
    problem(node_line(node), fmt::format("{}: expected a string, got {}", dotted, type_name(node)));
    return std::nullopt;
  }
  return std::string(node.as_string()->get());
}

std::optional<std::string> ModelLoader::read_string(const toml::table& t, std::string_view key,
                                                    const std::string& table_name) {
  const auto* node = required(t, key, table_name, node_line(t));
  if (!node) return std::nullopt;
  return string_of(*node, table_name + "." + std::string(key));
}

std::optional<std::vector<NamedLine>> ModelLoader::string_array(const toml::node& node,
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
std::vector<std::pair<std::string, const toml::table*>> ModelLoader::named_tables(
    const toml::table& t, const std::string& dotted) {
  std::vector<std::pair<std::string, const toml::table*>> out;
  for (const auto& [key, node] : t) {
    const std::string name(key.str());
    if (!node.is_table()) {
      problem(node_line(node),
              fmt::format("{}.{}: expected a table, got {}", dotted, name, type_name(node)));
      continue;
    }
    if (!valid_name(name)) {
      problem(node_line(node),
              fmt::format("[{}]: name '{}' must be non-empty and contain no '.'", dotted, name));
      continue;
    }
    out.emplace_back(name, node.as_table());
  }
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return node_line(*a.second) < node_line(*b.second);
  });
  return out;
}

// =======================================================================================
// The loader: numbers and options by the parameter table
// =======================================================================================
void ModelLoader::read_group(const toml::table& t, Group g, const std::string& table_name,
                             const std::vector<std::string>& extra) {
  const TableRule rule = group_def(g).table;
  std::vector<std::string> keys;
  for (const auto& row : parameter_table())
    if (row.group == g) keys.emplace_back(row.key);
  keys.insert(keys.end(), extra.begin(), extra.end());
  if (rule != TableRule::KeysOptional) check_keys(t, "[" + table_name + "]", keys);
  const long tl = node_line(t);
  for (const auto& row : parameter_table()) {
    if (row.group != g) continue;
    const std::string dotted = table_name + "." + std::string(row.key);
    if (!row.alternative.empty()) {
      read_alternative(t, row, table_name);
    } else if (const toml::node* node = t.get(row.key)) {
      store_number(*node, dotted);
    } else if (row.default_value) {
      store_default(dotted, row);
    } else if (rule != TableRule::KeysOptional) {
      (void)required(t, row.key, table_name, tl);  // reports the missing key
    }
  }
}

// One of a pair of keys (preload.force_N | preload.prestress_MPa): the one given is stored;
// neither is a missing key, both are refused at the second one's line.
void ModelLoader::read_alternative(const toml::table& t, const ParamDef& row,
                                   const std::string& table_name) {
  const toml::node* node = t.get(row.key);
  const toml::node* other = t.get(row.alternative);
  if (node && !other) store_number(*node, table_name + "." + std::string(row.key));
  if (!node && !other && row.key < row.alternative)
    problem(node_line(t), fmt::format("missing key '{}' (or '{}') in [{}]", row.key,
                                      row.alternative, table_name));
  if (!node || !other || row.key > row.alternative) return;  // the pair is checked once
  const long a = node_line(*node), b = node_line(*other);
  problem(std::max(a, b),
          fmt::format("[{}]: give {}.{} or {}.{}, not both (lines {} and {}): the force is "
                      "derived from the prestress of the first rod of stack.rods",
                      table_name, table_name, row.key, table_name, row.alternative, std::min(a, b),
                      std::max(a, b)));
}

void ModelLoader::read_group_table(const toml::table& parent, Group g, long missing_line,
                                   std::string_view instance) {
  const std::string dotted = schema::table_path(g, instance);
  const std::string key = dotted.substr(dotted.rfind('.') + 1);
  const TableRule rule = group_def(g).table;
  const toml::node* node = parent.get(key);
  if (!node && rule == TableRule::Optional) return;
  if (!node && rule == TableRule::Defaulted) {
    for (const auto& row : parameter_table())
      if (row.group == g) store_default(dotted + "." + std::string(row.key), row);
    return;
  }
  const toml::table* t = table_at(parent, key, dotted, missing_line);
  if (!t) return;
  if (rule == TableRule::Defaulted) spec_.option_lines["[" + dotted + "]"] = node_line(*node);
  read_group(*t, g, dotted);
}

void ModelLoader::read_meta(const toml::table& root) {
  const auto* t = table_at(root, "meta", "meta", 1);
  if (!t) return;
  check_keys(*t, "[meta]", {"name", "description"});
  for (std::string_view key : {"name", "description"}) {
    if (auto s = read_string(*t, key, "meta")) {
      const std::string dotted = "meta." + std::string(key);
      spec_.meta[dotted] = *s;
      spec_.option_lines[dotted] = node_line(*t->get(key));
    }
  }
}

// [options]: every row of the option table, a word from its list (or a boolean), parsed
// into spec_.options; then the rules between options.
void ModelLoader::read_options(const toml::table& root) {
  const auto* t = table_at(root, "options", "options", 1);
  if (!t) return;
  std::vector<std::string> keys;
  for (const auto& o : option_table()) keys.emplace_back(o.key);
  check_keys(*t, "[options]", keys);
  const long tl = node_line(*t);
  spec_.option_lines["[options]"] = tl;  // model save adds an omitted option below it
  bool ok = true;
  for (const auto& o : option_table()) {
    if (!o.default_word.empty() && !t->get(o.key)) continue;  // omitted: its default stands
    const auto* node = required(*t, o.key, "options", tl);
    ok = ok && node;
    if (!node) continue;
    const std::string dotted = "options." + std::string(o.key);
    spec_.option_lines[dotted] = node_line(*node);
    std::string word;
    if (o.boolean) {
      if (!node->is_boolean()) {
        problem(node_line(*node), fmt::format("{}: expected a boolean (true or false), got {}",
                                              dotted, type_name(*node)));
        ok = false;
        continue;
      }
      word = node->as_boolean()->get() ? "true" : "false";
    } else if (auto s = string_of(*node, dotted)) {
      word = *s;
    } else {
      ok = false;
      continue;
    }
    if (auto p = set_option_word(o, spec_.options, word)) {
      problem(node_line(*node), *p);
      ok = false;
    }
  }
  if (!ok) return;
  if (auto p = check_options(spec_.options)) problem(spec_.line_of(p->key), p->message);
}

}  // namespace io_detail

// =======================================================================================
// Entry points
// =======================================================================================
ModelSpec parse_model_spec(const std::string& toml_text, const std::string& source_name) {
  ModelSpec spec = io_detail::ModelLoader(toml_text, source_name).run();
  spec.text = toml_text;
  return spec;
}

ModelSpec load_model_spec(const std::string& path) {
  const std::string text = io_detail::read_text_file(path, "model file");
  return parse_model_spec(text, path);
}

ModelSpec builtin_model_spec() {
  return parse_model_spec(kBuiltinModelToml, io_detail::builtin_source_name());
}

Model load_model(const std::string& path) {
  return compile(path.empty() ? builtin_model_spec() : load_model_spec(path));
}

}  // namespace gmasim
