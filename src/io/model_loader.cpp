// Model files: TOML -> ModelSpec, validated field by field against the schema; the
// parameter table of `model show`; ModelSpec::get/set/line_of.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

#include "gmasim/errors.hpp"
#include "gmasim/io.hpp"
#include "io/text_io.hpp"
#include "io/toml_io.hpp"
#include "schema.hpp"

namespace gmasim {

// =======================================================================================
// Schema
// =======================================================================================
namespace schema {
namespace {

using R = Rule;

constexpr std::string_view kReserved[] = {
    "meta",  "options", "reference", "material",  "preload",          "magnet",
    "stack", "circuit", "sensor",    "mechanics", "thermal_expansion", "thermal_network"};

constexpr Field kReference[] = {{"T_ref_C", R::AboveAbsoluteZero}};

constexpr Field kMaterial[] = {
    {"Ms_A_per_m", R::Positive},
    {"lambda_s", R::Positive, "-"},
    {"sigma_lambda_Pa", R::Positive},
    {"Es_Pa", R::Positive},
    {"Tc_C", R::Any},  // cross-field: > reference.T_ref_C
    {"rho0_ohm_m", R::Positive},
    {"drho_dT_ohm_m_per_K", R::Any},
    {"beta_per_K", R::Any},
    {"chi_m", R::Positive, "-"},  // susceptibility, not metres
    {"x", R::Positive, "-"},
    {"alpha_thermal_per_K", R::NonNegative},
};

constexpr Field kPreload[] = {{"force_N", R::NonNegative}};

constexpr Field kMagnet[] = {{"alpha_pm1_per_K", R::Any}, {"alpha_pm2_per_K2", R::Any}};

constexpr Field kRod[] = {
    {"outer_diameter_m", R::Positive},
    {"inner_diameter_m", R::NonNegative},  // cross-field: < outer_diameter_m
    {"length_m", R::Positive},
    {"mass_kg", R::Positive},
    {"k_f", R::Positive, "-"},
    {"k_j", R::Positive, "-"},
    {"damping_N_s_per_m", R::Positive},
};

constexpr Field kJa[] = {
    {"a0_A_per_m", R::Positive}, {"alpha0", R::Any},     {"c0", R::UnitInterval},
    {"k0_A_per_m", R::Positive}, {"beta1", R::Positive}, {"beta2", R::Positive},
    {"beta3", R::Positive},
};

constexpr Field kElement[] = {
    {"mass_kg", R::NonNegative},
    {"stiffness_N_per_m", R::Positive},
    {"damping_N_s_per_m", R::Positive},
};

// [mechanics.output_stage] (optional): the output head and sensor on a compliant mount.
constexpr Field kOutputStage[] = {
    {"mass_kg", R::Positive},
    {"stiffness_N_per_m", R::Positive},
    {"damping_N_s_per_m", R::NonNegative},
};

constexpr Field kSleeveModulus[] = {{"Et_Pa", R::Positive}, {"dEt_dT_Pa_per_C", R::Any}};

constexpr Field kSleeve[] = {
    {"mass_kg", R::Positive},
    {"damping_N_s_per_m", R::Positive},
    {"alpha_thermal_per_K", R::NonNegative},
    {"l1_m", R::Positive},
    {"l2_m", R::Positive},
    {"l3_m", R::Positive},
    {"A1_m2", R::Positive},
    {"A2_m2", R::Positive},
    {"A3_m2", R::Positive},
};


constexpr Field kBranchNumbers[] = {{"coil_turns", R::NonNegative, "turns"}, {"pm_mmf_At", R::Any}};

struct Suffix {
  std::string_view suffix, unit;
};
// Longer suffixes first where one ends another ("_ohm_m" before "_m", "_Pa_per_C" before "_C").
constexpr Suffix kSuffixes[] = {
    {"_J_per_kg_K", "J/(kg K)"},
    {"_J_per_K", "J/K"},
    {"_W_per_K", "W/K"},
    {"_ohm", "ohm"},
    {"_ohm_m_per_K", "ohm m/K"},
    {"_N_s_per_m", "N s/m"},
    {"_Pa_per_C", "Pa/degC"},
    {"_A_per_m", "A/m"},
    {"_N_per_m", "N/m"},
    {"_per_K2", "1/K^2"},
    {"_per_K", "1/K"},
    {"_per_H", "1/H"},
    {"_ohm_m", "ohm m"},
    {"_m2", "m^2"},
    {"_kg", "kg"},
    {"_Pa", "Pa"},
    {"_At", "A-turns"},
    {"_m", "m"},
    {"_C", "degC"},
    {"_N", "N"},
};

std::optional<Field> find_field(std::span<const Field> fields, std::string_view key) {
  for (const auto& f : fields)
    if (f.key == key) return f;
  return std::nullopt;
}

std::vector<std::string> split_dotted(const std::string& dotted) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const auto dot = dotted.find('.', start);
    parts.push_back(dotted.substr(start, dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return parts;
}

bool is_rod(const ModelSpec& spec, const std::string& name) {
  return std::find(spec.rods.begin(), spec.rods.end(), name) != spec.rods.end();
}

// [thermal_network] (optional, self-heating; docs/model.md, "Self-heating"): every key has a
// default, used (with this provenance) when the key or the whole table is absent.
constexpr DefaultedField kThermalNetwork[] = {
    {{"coil_resistance_ohm", R::Positive}, 1.5,
     "default: estimate for the MDMA coil (720 turns of ~0.8 mm copper), at reference.T_ref_C"},
    {{"coil_alpha_per_K", R::NonNegative}, 3.93e-3, "default: copper, handbook value"},
    {{"coil_heat_capacity_J_per_K", R::Positive}, 80.0,
     "default: estimate, ~0.2 kg of copper x 385 J/(kg K)"},
    {{"rod_specific_heat_J_per_kg_K", R::Positive}, 350.0,
     "default: Terfenol-D, ~0.35 kJ/(kg K) (manufacturer data)"},
    {{"housing_heat_capacity_J_per_K", R::Positive}, 450.0,
     "default: estimate, ~1 kg of steel x 460 J/(kg K)"},
    {{"coil_to_rods_W_per_K", R::Positive}, 0.5,
     "default: estimate, conduction across the coil former and air gap"},
    {{"coil_to_housing_W_per_K", R::Positive}, 1.0, "default: estimate, coil potted to the housing"},
    {{"rods_to_housing_W_per_K", R::Positive}, 0.5,
     "default: estimate, conduction through the magnetizers and end caps"},
    {{"housing_to_ambient_W_per_K", R::Positive}, 0.4,
     "default: estimate, natural convection ~10 W/(m^2 K) over ~0.04 m^2"},
};

// Tables a single-rod actuator may leave out (issue 9, item 7): their keys default.
constexpr DefaultedField kMagnetDefaults[] = {
    {kMagnet[0], 0.0, "default: no permanent-magnet temperature coefficient (or no magnet)"},
    {kMagnet[1], 0.0, "default: no permanent-magnet temperature coefficient (or no magnet)"},
};
constexpr DefaultedField kSleeveModulusDefaults[] = {
    {kSleeveModulus[0], 200e9, "default: steel; used only by [mechanics.sleeves]"},
    {kSleeveModulus[1], 0.0, "default: temperature-independent"},
};
// [thermal_expansion] (eq. 21) when absent: the rods' own expansion over the longest rod,
// nothing else in the stack expands (rod_length_m = 0 means "the longest rod").
constexpr DefaultedField kThermalDefaults[] = {
    {{"rod_length_m", R::NonNegative}, 0.0, "default: 0 = the longest rod of stack.rods"},
    {{"magnetizer_length_m", R::NonNegative}, 0.0, "default: no magnetizer in the stack"},
    {{"magnetizer_alpha_per_K", R::NonNegative}, 0.0, "default: no magnetizer in the stack"},
    {{"output_rod_length_m", R::NonNegative}, 0.0, "default: no output rod in the stack"},
    {{"output_rod_alpha_per_K", R::NonNegative}, 0.0, "default: no output rod in the stack"},
    {{"sleeve_length_m", R::NonNegative}, 0.0, "default: no sleeve in the stack"},
    {{"sleeve_alpha_per_K", R::NonNegative}, 0.0, "default: no sleeve in the stack"},
};

}  // namespace

std::span<const std::string_view> reserved_tables() { return kReserved; }
std::span<const Field> reference_fields() { return kReference; }
std::span<const Field> material_fields() { return kMaterial; }
std::span<const Field> preload_fields() { return kPreload; }
std::span<const Field> magnet_fields() { return kMagnet; }
std::span<const Field> rod_fields() { return kRod; }
std::span<const Field> ja_fields() { return kJa; }
std::span<const Field> element_fields() { return kElement; }
std::span<const Field> sleeve_modulus_fields() { return kSleeveModulus; }
std::span<const Field> output_stage_fields() { return kOutputStage; }
std::span<const Field> sleeve_fields() { return kSleeve; }
std::span<const DefaultedField> thermal_network_defaults() { return kThermalNetwork; }
std::span<const DefaultedField> magnet_defaults() { return kMagnetDefaults; }
std::span<const DefaultedField> sleeve_modulus_defaults() { return kSleeveModulusDefaults; }
std::span<const DefaultedField> thermal_expansion_defaults() { return kThermalDefaults; }
std::span<const Field> branch_number_fields() { return kBranchNumbers; }

std::string unit_from_suffix(std::string_view key) {
  for (const auto& s : kSuffixes)
    if (key.size() > s.suffix.size() && key.ends_with(s.suffix)) return std::string(s.unit);
  return "-";
}

std::string unit_of(const Field& f) {
  if (!f.unit.empty()) return std::string(f.unit);
  return unit_from_suffix(f.key);
}

std::optional<Field> field_of(const ModelSpec& spec, const std::string& dotted) {
  const auto p = split_dotted(dotted);
  if (p.size() == 2) {
    if (p[0] == "reference") return find_field(kReference, p[1]);
    if (p[0] == "material") return find_field(kMaterial, p[1]);
    if (p[0] == "preload") return find_field(kPreload, p[1]);
    if (p[0] == "magnet") return find_field(kMagnet, p[1]);
    if (p[0] == "thermal_expansion")
      for (const auto& d : kThermalDefaults)
        if (d.field.key == p[1]) return d.field;
    if (p[0] == "thermal_network")
      for (const auto& d : kThermalNetwork)
        if (d.field.key == p[1]) return d.field;
    if (is_rod(spec, p[0])) return find_field(kRod, p[1]);
  } else if (p.size() == 3) {
    if (p[0] == "mechanics" && p[1] == "sleeve_modulus") return find_field(kSleeveModulus, p[2]);
    if (p[0] == "mechanics" && p[1] == "output_stage") return find_field(kOutputStage, p[2]);
    if (p[0] == "circuit" && p[1] == "reluctances_per_H") return kReluctanceField;
    if (p[1] == "ja" && is_rod(spec, p[0])) return find_field(kJa, p[2]);
  } else if (p.size() == 4) {
    if (p[0] == "mechanics" && p[1] == "elements") return find_field(kElement, p[3]);
    if (p[0] == "mechanics" && p[1] == "sleeves") return find_field(kSleeve, p[3]);
    if (p[0] == "circuit" && p[1] == "branches") return find_field(kBranchNumbers, p[3]);
  }
  return std::nullopt;
}

std::string value_with_unit(const std::string& dotted, double value, const std::string& unit) {
  if (unit.empty() || unit == "-") return fmt::format("{} = {:g}", dotted, value);
  return fmt::format("{} = {:g} {}", dotted, value, unit);
}

std::optional<std::string> check_value(const ModelSpec& spec, const std::string& dotted,
                                       double value) {
  const auto field = field_of(spec, dotted);
  const std::string unit = field ? unit_of(*field) : std::string("-");
  auto bad = [&](const std::string& rule) {
    return fmt::format("{}: {}", value_with_unit(dotted, value, unit), rule);
  };
  if (std::isnan(value)) return bad("NaN is not allowed: every number must be finite");
  if (std::isinf(value)) return bad("Inf is not allowed: every number must be finite");
  // No SI value of the model is below 1e-30 or above 1e30 in magnitude (the smallest, eq. 1's
  // alpha_pm2, is ~1e-7 /K^2; the largest, a modulus, ~1e11 Pa): such a number is a typo or
  // a hostile input, and a subnormal one turns into inf/NaN downstream (issue 8).
  if (value != 0.0 && !(std::fabs(value) >= 1e-30 && std::fabs(value) <= 1e30))
    return bad(
        "outside the range of any physical value of the model (1e-30 <= |v| <= 1e30, "
        "or 0)");
  if (!field) return std::nullopt;
  switch (field->rule) {
    case R::Any:
      break;
    case R::Positive:
      if (!(value > 0.0)) return bad("must be > 0");
      break;
    case R::NonNegative:
      if (!(value >= 0.0)) return bad("must be >= 0");
      break;
    case R::UnitInterval:
      if (!(value >= 0.0 && value < 1.0)) return bad("must be in [0, 1)");
      break;
    case R::AboveAbsoluteZero:
      if (!(value > -273.15)) return bad("must be > -273.15 degC (absolute zero)");
      break;
  }
  // Cross-field rules, checked from the dependent side.
  const auto p = split_dotted(dotted);
  if (p.size() == 2 && p[1] == "inner_diameter_m" && is_rod(spec, p[0])) {
    const auto outer = spec.params.find(p[0] + ".outer_diameter_m");
    if (outer != spec.params.end() && std::isfinite(outer->second.value) &&
        !(value < outer->second.value)) {
      return bad(fmt::format("must be < {}.outer_diameter_m = {:g} m", p[0], outer->second.value));
    }
  }
  if (dotted == "material.Tc_C") {
    const auto tref = spec.params.find("reference.T_ref_C");
    if (tref != spec.params.end() && std::isfinite(tref->second.value) &&
        !(value > tref->second.value)) {
      return bad(fmt::format("must be > reference.T_ref_C = {:g} degC", tref->second.value));
    }
  }
  return std::nullopt;
}

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

// =======================================================================================
// ModelSpec accessors
// =======================================================================================
namespace {

// Exact name, else the unique parameter "<dotted>_<unit suffix>"; nullopt if none;
// throws if the prefix is ambiguous.
std::optional<std::string> try_resolve(const ModelSpec& spec, const std::string& dotted) {
  if (spec.params.count(dotted)) return dotted;
  const std::string prefix = dotted + "_";
  std::vector<std::string> matches;
  for (auto it = spec.params.lower_bound(prefix);
       it != spec.params.end() && it->first.starts_with(prefix); ++it) {
    if (it->first.find('.', prefix.size()) == std::string::npos) matches.push_back(it->first);
  }
  if (matches.size() == 1) return matches.front();
  if (matches.size() > 1) {
    throw InputError(
        located(spec.source, 0,
                fmt::format("ambiguous parameter '{}': matches {}", dotted, join(matches, ", "))));
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
                              group, join(names, ", "))));
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
                                       dotted, join(groups, ", "))));
}

std::string resolve(const ModelSpec& spec, const std::string& dotted) {
  if (auto key = try_resolve(spec, dotted)) return *key;
  throw_unknown(spec, dotted);
}

}  // namespace

double ModelSpec::get(const std::string& dotted) const {
  return params.at(resolve(*this, dotted)).value;
}

void ModelSpec::set(const std::string& dotted, double value) {
  const std::string key = resolve(*this, dotted);
  ParamValue& pv = params.at(key);
  const double old = pv.value;
  pv.value = value;
  // The value itself, and the cross-field rules that depend on it.
  std::vector<std::string> to_check = {key};
  if (key.ends_with(".outer_diameter_m")) {
    to_check.push_back(key.substr(0, key.size() - std::string_view("outer_diameter_m").size()) +
                       "inner_diameter_m");
  }
  if (key == "reference.T_ref_C") to_check.emplace_back("material.Tc_C");
  for (const auto& k : to_check) {
    const auto it = params.find(k);
    if (it == params.end()) continue;
    if (auto problem = schema::check_value(*this, k, it->second.value)) {
      pv.value = old;
      throw InputError(
          located(source, pv.line, fmt::format("cannot set {} = {:g}: {}", key, value, *problem)));
    }
  }
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
