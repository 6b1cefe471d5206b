// The parameter table (gmasim/model/parameters.hpp): every number of the shipped model files has
// its row, every row lands in its own Model field and nowhere else, units agree with key
// suffixes, options parse once and round-trip, and docs/parameters.md is the table.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/parameters.hpp"

using ::testing::HasSubstr;

namespace {

std::string read_source_file(const std::string& rel) {
  std::ifstream in(std::string(GMASIM_SOURCE_DIR) + "/" + rel);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<gmasim::ModelSpec> shipped_specs() {
  std::vector<gmasim::ModelSpec> specs = {gmasim::builtin_model_spec()};
  for (const char* f : {"models/mdma_printed.toml", "models/single_rod.toml"})
    specs.push_back(gmasim::load_model_spec(std::string(GMASIM_SOURCE_DIR) + "/" + f));
  return specs;
}

// The instance index of the table of `dotted` within its group (rod, element, sleeve or
// branch index; 0 for single tables).
std::size_t instance_of(const gmasim::ModelSpec& spec, const gmasim::ParamDef& row,
                        const std::string& dotted) {
  const std::string table = dotted.substr(0, dotted.rfind('.'));
  auto index = [&](const std::vector<std::string>& names, const std::string& name) {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == name) return i;
    ADD_FAILURE() << dotted << ": no instance " << name;
    return std::size_t{0};
  };
  const std::string last = table.substr(table.rfind('.') + 1);
  switch (row.group) {
    case gmasim::Group::Rod:
      return index(spec.rods, table);
    case gmasim::Group::RodJa:
      return index(spec.rods, table.substr(0, table.find('.')));
    case gmasim::Group::Element:
      return index(spec.element_names, last);
    case gmasim::Group::Sleeve:
      return index(spec.sleeve_names, last);
    case gmasim::Group::Branch: {
      std::vector<std::string> names;
      for (const auto& b : spec.branches) names.push_back(b.name);
      return index(names, last);
    }
    default:
      return 0;
  }
}

std::size_t reluctance_count(const gmasim::ModelSpec& spec) {
  std::size_t n = 0;
  for (const auto& [name, pv] : spec.params) n += name.starts_with("circuit.reluctances_per_H.");
  return n;
}

// A value that obeys the row's rules and differs from v.
double changed(const gmasim::ParamDef& row, double v) {
  if (row.key == "inner_diameter_m") return 0.5 * v;  // stays below the outer diameter
  if (row.rule == gmasim::Rule::UnitInterval) return v == 0.0 ? 0.25 : 0.5 * v;
  return v == 0.0 ? 1e-3 : 1.25 * v;
}

}  // namespace

TEST(ParameterTable, EveryNumberOfTheShippedModelsHasItsRow) {
  for (const auto& spec : shipped_specs()) {
    for (const auto& [name, pv] : spec.params) {
      const gmasim::ParamDef* def = spec.def_of(name);
      ASSERT_NE(def, nullptr) << spec.source << ": " << name;
      EXPECT_EQ(spec.unit_of(name), def->unit) << name;
      EXPECT_FALSE(def->doc.empty()) << name;
    }
  }
}

TEST(ParameterTable, EveryRowOfAFixedTableIsInTheBuiltInModel) {
  const auto spec = gmasim::builtin_model_spec();
  std::size_t checked = 0;
  for (const auto& row : gmasim::parameter_table()) {
    if (row.group == gmasim::Group::Reluctance || row.group == gmasim::Group::Branch) continue;
    // Table 1 gives reluctances, no part geometry: the MDMA has no such table.
    if (row.group == gmasim::Group::ReluctanceGeometry) {
      EXPECT_TRUE(spec.reluctance_geometry_names.empty());
      continue;
    }
    const auto law = gmasim::group_def(row.group).law;  // another magnetisation law's table
    if (law && *law != spec.options.magnetisation_law) continue;
    const std::string path(gmasim::group_def(row.group).path);
    std::vector<std::string> tables = {path};
    if (row.group == gmasim::Group::Rod) tables = spec.rods;
    if (row.group == gmasim::Group::RodJa) {
      tables.clear();
      for (const auto& r : spec.rods) tables.push_back(r + ".ja");
    }
    if (row.group == gmasim::Group::Element) {
      tables.clear();
      for (const auto& e : spec.element_names) tables.push_back("mechanics.elements." + e);
    }
    if (row.group == gmasim::Group::Sleeve) {
      tables.clear();
      for (const auto& s : spec.sleeve_names) tables.push_back("mechanics.sleeves." + s);
    }
    for (const auto& t : tables) {
      // One key of a pair (preload.force_N | preload.prestress_MPa): the other is given.
      if (!row.alternative.empty() && spec.params.count(t + "." + std::string(row.alternative)))
        continue;
      EXPECT_EQ(spec.params.count(t + "." + std::string(row.key)), 1u) << t << "." << row.key;
      ++checked;
    }
  }
  EXPECT_EQ(checked + reluctance_count(spec) + 2 /* phi4's sources */, spec.params.size());
}

// Each number of the built-in model, changed alone, moves the Model field its row names to
// the new value, and no other number lands there.
TEST(ParameterTable, EachNumberLandsInTheFieldItsRowNames) {
  const auto spec = gmasim::builtin_model_spec();
  const gmasim::Model base = gmasim::compile(spec);
  for (const auto& [name, pv] : spec.params) {
    const gmasim::ParamDef& row = *spec.def_of(name);
    if (row.lands == nullptr) continue;  // reluctances: see ReluctancesSumIntoTheirBranches
    const std::size_t i = instance_of(spec, row, name);
    auto edited = spec;
    const double v = changed(row, pv.value);
    edited.set(name, v);
    gmasim::Model m = gmasim::compile(edited);
    EXPECT_EQ(row.lands(m, i), v) << name << " lands in " << row.lands_in;
    gmasim::Model b = base;
    EXPECT_EQ(row.lands(b, i), pv.value) << name;
  }
}

TEST(ParameterTable, NoTwoNumbersLandInOnePlace) {
  const auto spec = gmasim::builtin_model_spec();
  gmasim::Model m = gmasim::compile(spec);
  std::map<const double*, std::string> owner;
  for (const auto& [name, pv] : spec.params) {
    const gmasim::ParamDef& row = *spec.def_of(name);
    if (row.lands == nullptr) continue;
    const double* at = &row.lands(m, instance_of(spec, row, name));
    const auto [it, fresh] = owner.emplace(at, name);
    EXPECT_TRUE(fresh) << name << " and " << it->second << " land in the same field";
  }
  EXPECT_EQ(owner.size(), spec.params.size() - reluctance_count(spec));
}

TEST(ParameterTable, ReluctancesSumIntoTheirBranches) {
  auto spec = gmasim::builtin_model_spec();
  const gmasim::Model base = gmasim::compile(spec);
  const double was = spec.get("circuit.reluctances_per_H.R_pm");
  spec.set("circuit.reluctances_per_H.R_pm", 2e6);  // only phi4's series names R_pm
  const gmasim::Model m = gmasim::compile(spec);
  for (std::size_t k = 0; k < m.circuit.branches.size(); ++k) {
    const double d = m.circuit.branches[k].fixed_reluctance_per_H -
                     base.circuit.branches[k].fixed_reluctance_per_H;
    if (m.circuit.branches[k].name == "phi4")
      EXPECT_NEAR(d, 2e6 - was, 1e-9 * was);
    else
      EXPECT_EQ(d, 0.0) << m.circuit.branches[k].name;
  }
}

// A unit suffix of a key names its row's unit (keys without a suffix are dimensionless or
// say their unit in the row: chi_m is a susceptibility, coil_turns counts turns).
TEST(ParameterTable, UnitsAgreeWithKeySuffixes) {
  const std::pair<std::string_view, std::string_view> suffixes[] = {{"_J_per_kg_K", "J/(kg K)"},
                                                                    {"_J_per_K", "J/K"},
                                                                    {"_W_per_K", "W/K"},
                                                                    {"_ohm_m_per_K", "ohm m/K"},
                                                                    {"_N_s_per_m", "N s/m"},
                                                                    {"_Pa_per_C", "Pa/degC"},
                                                                    {"_kg_per_m3", "kg/m^3"},
                                                                    {"_A_per_m", "A/m"},
                                                                    {"_N_per_m", "N/m"},
                                                                    {"_per_K2", "1/K^2"},
                                                                    {"_per_K", "1/K"},
                                                                    {"_ohm_m", "ohm m"},
                                                                    {"_ohm", "ohm"},
                                                                    {"_m2", "m^2"},
                                                                    {"_kg", "kg"},
                                                                    {"_MPa", "MPa"},
                                                                    {"_Pa", "Pa"},
                                                                    {"_At", "A-turns"},
                                                                    {"_m", "m"},
                                                                    {"_C", "degC"},
                                                                    {"_N", "N"}};
  const std::set<std::string_view> named_unit = {"chi_m", "coil_turns", "*"};
  for (const auto& row : gmasim::parameter_table()) {
    if (named_unit.count(row.key)) continue;
    std::string_view want = "-";
    for (const auto& [suffix, unit] : suffixes) {
      if (row.key.size() > suffix.size() && row.key.ends_with(suffix)) {
        want = unit;
        break;
      }
    }
    EXPECT_EQ(row.unit, want) << row.key;
  }
}

TEST(ParameterTable, DefaultsOnlyInDefaultedTablesAndObeyTheirRules) {
  for (const auto& row : gmasim::parameter_table()) {
    // A defaulted table defaults every key; a required table may default a key that a model
    // need not state (rodN.joint_gap_m: a rod without joints); an optional table has none (its
    // presence switches a feature on, and then every key is stated).
    const auto table = gmasim::group_def(row.group).table;
    if (table == gmasim::TableRule::Defaulted) {
      EXPECT_TRUE(row.default_value.has_value()) << row.key;
    }
    if (table == gmasim::TableRule::Optional || table == gmasim::TableRule::KeysOptional) {
      EXPECT_FALSE(row.default_value.has_value()) << row.key;
    }
    EXPECT_EQ(!row.default_provenance.empty(), row.default_value.has_value()) << row.key;
    if (!row.default_value) continue;
    // A derived key (gmasim/model/derived.hpp): its "default" is the derivation, filled in at
    // load from the geometry, never the row's placeholder.
    if (row.default_provenance.starts_with("derived:")) {
      EXPECT_EQ(row.key, "mass_kg");
      continue;
    }
    if (row.rule == gmasim::Rule::Positive) {
      EXPECT_GT(*row.default_value, 0.0) << row.key;
    }
    EXPECT_TRUE(row.default_provenance.starts_with("default:")) << row.key;
  }
}

TEST(OptionTable, DefaultOptionsAreTheBuiltInReadings) {
  EXPECT_EQ(gmasim::Options{}, gmasim::builtin_model_spec().options);
  EXPECT_EQ(gmasim::Options{}, gmasim::compile(gmasim::builtin_model_spec()).options);
}

TEST(OptionTable, EveryWordRoundTrips) {
  for (const auto& def : gmasim::option_table()) {
    for (const auto& c : def.choices) {
      gmasim::Options o;
      o.eq10_scale = gmasim::Eq10Scale::RoomReferenced;
      EXPECT_EQ(gmasim::set_option_word(def, o, c.word), std::nullopt) << def.key;
      EXPECT_EQ(gmasim::option_word(def, o), c.word) << def.key;
      EXPECT_EQ(def.reads(o), c.value) << def.key;
    }
    gmasim::Options o;
    const auto problem = gmasim::set_option_word(def, o, "nonsense");
    ASSERT_TRUE(problem.has_value());
    EXPECT_THAT(*problem, HasSubstr("must be one of: "));
    EXPECT_EQ(o, gmasim::Options{}) << "a refused word changes nothing";
  }
}

TEST(OptionTable, SetOptionParsesOnceAndRefusesMixedReadings) {
  auto spec = gmasim::builtin_model_spec();
  spec.set_option("options.magnetic_state", "printed");
  EXPECT_EQ(spec.options.magnetic_state, gmasim::MagneticState::Printed);
  spec.set_option("eq10_shape_law", "printed");
  spec.set_option("eq10_temperature_scale", "kelvin");
  EXPECT_EQ(gmasim::compile(spec).options.eq10_scale, gmasim::Eq10Scale::Kelvin);
  try {
    spec.set_option("eq10_shape_law", "mean_field");  // with kelvin: mixed references
    ADD_FAILURE() << "accepted mean_field with kelvin";
  } catch (const gmasim::InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("mixes reference temperatures"));
  }
  EXPECT_EQ(spec.options.shape_law, gmasim::ShapeLaw::Printed) << "a refused word changes nothing";
  try {
    spec.set_option("options.magnetic_state", "weird");
    ADD_FAILURE() << "accepted a bad word";
  } catch (const gmasim::InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("options.magnetic_state = \"weird\": must be one of: "
                                    "printed, consistent"));
  }
  try {
    spec.set_option("options.colour", "red");
    ADD_FAILURE() << "accepted an unknown option";
  } catch (const gmasim::InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown option 'options.colour'; known: options.stress_sign"));
  }
}

// Several options set at once are judged as a whole: the rule between eq. 10's options holds
// for the result, whatever the order of the assignments (--set, Model.with_params).
TEST(OptionTable, AssignmentsAreCheckedTogetherInAnyOrder) {
  const auto base = gmasim::builtin_model_spec();  // mean_field, room_referenced
  for (const auto& order : {std::vector<std::string>{"options.eq10_temperature_scale=kelvin",
                                                     "options.eq10_shape_law=printed"},
                            std::vector<std::string>{"options.eq10_shape_law=printed",
                                                     "options.eq10_temperature_scale=kelvin"}}) {
    const auto spec = gmasim::apply_assignments(base, order);
    EXPECT_EQ(spec.options.eq10_scale, gmasim::Eq10Scale::Kelvin);
    EXPECT_EQ(spec.options.shape_law, gmasim::ShapeLaw::Printed);
  }
  try {
    (void)gmasim::apply_assignments(base, {"options.eq10_temperature_scale=kelvin"});
    ADD_FAILURE() << "accepted mean_field with kelvin";
  } catch (const gmasim::InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("mixes reference temperatures"));
  }
}

TEST(ParameterTable, CompileHoldsAHandEditedSpecToTheRules) {
  auto spec = gmasim::builtin_model_spec();
  spec.params.at("rod2.length_m").value = -0.03;  // bypasses set(): compile still refuses it
  try {
    (void)gmasim::compile(spec);
    ADD_FAILURE() << "compiled a negative length";
  } catch (const gmasim::InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("rod2.length_m = -0.03 m: must be > 0"));
  }
  spec = gmasim::builtin_model_spec();
  spec.params.at("material.Tc_C").value = 15.0;
  try {
    (void)gmasim::compile(spec);
    ADD_FAILURE() << "compiled T_c below T_ref";
  } catch (const gmasim::InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("material.Tc_C = 15 degC: must be > reference.T_ref_C"));
  }
}

TEST(ParameterTable, SetChecksTheCrossRulesThatDependOnTheValue) {
  auto spec = gmasim::builtin_model_spec();
  EXPECT_THROW(spec.set("reference.T_ref_C", 400.0), gmasim::InputError);  // above T_c
  EXPECT_EQ(spec.get("reference.T_ref_C"), 20.0) << "a refused value changes nothing";
  EXPECT_THROW(spec.set("rod1.outer_diameter_m", 0.01), gmasim::InputError);  // inner: 15 mm
  EXPECT_EQ(spec.get("rod1.outer_diameter_m"), 0.020);
  spec.set("rod1.outer_diameter_m", 0.021);
  EXPECT_EQ(gmasim::compile(spec).rods[0].outer_diameter_m, 0.021);
}

TEST(ParameterTable, DocsParametersMdIsTheTable) {
  const std::string md = gmasim::parameters_markdown();
  EXPECT_EQ(read_source_file("docs/parameters.md"), md)
      << "docs/parameters.md is stale: regenerate it with `gmasim model params --markdown > "
         "docs/parameters.md`";
  for (const auto& row : gmasim::parameter_table())
    EXPECT_THAT(md, HasSubstr(fmt::format("| `{}` | {} |", row.key, row.unit)));
  for (const auto& o : gmasim::option_table())
    EXPECT_THAT(md, HasSubstr(fmt::format("| `{}` |", o.key)));
}
