// The model-file schema (field lists, units, value rules) and ModelSpec::get/set/line_of:
// the rules a parameter obeys wherever it is set (the loader of src/io, --set, identify).
#include "model/schema.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "gmasim/errors.hpp"

namespace gmasim {

// =======================================================================================
// Schema
// =======================================================================================
namespace schema {
namespace {

using R = Rule;

constexpr std::string_view kReserved[] = {
    "meta",  "options", "reference", "material",  "preload",           "magnet",
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
    {{"coil_resistance_ohm", R::Positive},
     1.5,
     "default: estimate for the MDMA coil (720 turns of ~0.8 mm copper), at reference.T_ref_C"},
    {{"coil_alpha_per_K", R::NonNegative}, 3.93e-3, "default: copper, handbook value"},
    {{"coil_heat_capacity_J_per_K", R::Positive},
     80.0,
     "default: estimate, ~0.2 kg of copper x 385 J/(kg K)"},
    {{"rod_specific_heat_J_per_kg_K", R::Positive},
     350.0,
     "default: Terfenol-D, ~0.35 kJ/(kg K) (manufacturer data)"},
    {{"housing_heat_capacity_J_per_K", R::Positive},
     450.0,
     "default: estimate, ~1 kg of steel x 460 J/(kg K)"},
    {{"coil_to_rods_W_per_K", R::Positive},
     0.5,
     "default: estimate, conduction across the coil former and air gap"},
    {{"coil_to_housing_W_per_K", R::Positive},
     1.0,
     "default: estimate, coil potted to the housing"},
    {{"rods_to_housing_W_per_K", R::Positive},
     0.5,
     "default: estimate, conduction through the magnetizers and end caps"},
    {{"housing_to_ambient_W_per_K", R::Positive},
     0.4,
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

}  // namespace schema

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
