// Model files: the built-in file, describe_model, ModelSpec accessors and the writer of
// changed models (model_toml, apply_assignments).
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/validate.hpp"
#include "model_file_fixture.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;
using namespace gmasim_test;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

// =======================================================================================
// The built-in model
// =======================================================================================
TEST(ModelFile, BuiltinParses) {
  EXPECT_EQ(gmasim::builtin_model_spec().source,
            std::string(gmasim::kBuiltinModelName) + " (built-in)");
  const auto spec = fixture_spec();
  EXPECT_EQ(spec.rods, (std::vector<std::string>{"rod1", "rod2", "rod3"}));
  EXPECT_EQ(spec.reference_node, "0");
  EXPECT_EQ(spec.nodes, (std::vector<std::string>{"A", "B", "C", "D", "E", "F", "G"}));
  EXPECT_EQ(spec.nodes_line, line_of(builtin_text(), "nodes = ["));
  ASSERT_EQ(spec.branches.size(), 15u);
  EXPECT_EQ(spec.branches[0].name, "phi1");
  EXPECT_EQ(spec.branches[0].rod, "rod1");
  EXPECT_EQ(spec.branches[3].series, (std::vector<std::string>{"R_shell", "R_m", "R_pm"}));
  EXPECT_EQ(spec.branches[3].from, "0");
  EXPECT_EQ(spec.branches[3].to, "A");
  EXPECT_EQ(spec.flux_sensor_branches, (std::vector<std::string>{"phi1", "phi2", "phi3"}));
  EXPECT_EQ(spec.element_names, (std::vector<std::string>{"M1", "M2", "M3", "M4", "s", "dh"}));
  EXPECT_EQ(spec.sleeve_names, (std::vector<std::string>{"t1", "t2"}));
  EXPECT_EQ(spec.chains.at("rod3"), (std::vector<std::string>{"s", "dh"}));
  EXPECT_EQ(spec.options.stress_sign, gmasim::StressSign::CompressionNegative);
  EXPECT_FALSE(spec.options.thermal_expansion_in_output);
  EXPECT_TRUE(spec.options.geometry_thermal_expansion);
  EXPECT_EQ(spec.meta.at("meta.name"), "MDMA");

  const std::string text = builtin_text();
  const auto& k0 = spec.params.at("rod1.ja.k0_A_per_m");
  EXPECT_EQ(k0.value, 3032.0);
  EXPECT_EQ(spec.unit_of("rod1.ja.k0_A_per_m"), "A/m");
  EXPECT_EQ(k0.provenance, "Table 4");
  EXPECT_EQ(k0.line, line_of(text, "k0_A_per_m = 3032.0"));
  EXPECT_EQ(spec.params.at("circuit.branches.phi4.coil_turns").value, 720.0);
  EXPECT_EQ(spec.unit_of("circuit.branches.phi4.pm_mmf_At"), "A-turns");
  EXPECT_EQ(spec.params.count("circuit.branches.phi1.coil_turns"), 0u);
}

TEST(ModelFile, UnitsComeFromKeySuffixes) {
  const auto spec = fixture_spec();
  const std::pair<const char*, const char*> expected[] = {
      {"material.Ms_A_per_m", "A/m"},
      {"material.lambda_s", "-"},
      {"material.sigma_lambda_Pa", "Pa"},
      {"material.Tc_C", "degC"},
      {"material.rho0_ohm_m", "ohm m"},
      {"material.drho_dT_ohm_m_per_K", "ohm m/K"},
      {"material.beta_per_K", "1/K"},
      {"material.chi_m", "-"},  // susceptibility, not metres
      {"material.x", "-"},
      {"magnet.alpha_pm2_per_K2", "1/K^2"},
      {"preload.force_N", "N"},
      {"rod1.length_m", "m"},
      {"rod1.mass_kg", "kg"},
      {"rod1.k_f", "-"},
      {"rod1.damping_N_s_per_m", "N s/m"},
      {"mechanics.elements.dh.stiffness_N_per_m", "N/m"},
      {"mechanics.sleeves.t1.A2_m2", "m^2"},
      {"mechanics.sleeve_modulus.dEt_dT_Pa_per_C", "Pa/degC"},
      {"circuit.reluctances_per_H.R_m", "1/H"},  // not metres
      {"circuit.branches.phi4.coil_turns", "turns"},
      {"reference.T_ref_C", "degC"},
  };
  for (const auto& [name, unit] : expected) {
    ASSERT_EQ(spec.params.count(name), 1u) << name;
    EXPECT_EQ(spec.unit_of(name), unit) << name;
  }
}

TEST(ModelFile, IntegersAreNumbers) {
  const auto spec = gmasim::parse_model_spec(
      replace_once(builtin_text(), "force_N = 500.0", "force_N = 500"), "int.toml");
  EXPECT_EQ(spec.get("preload.force_N"), 500.0);
}

TEST(ModelFile, DescribeGivesProvenanceForEveryParameter) {
  const auto spec = gmasim::builtin_model_spec();  // the real built-in file: its provenance
  const auto rows = gmasim::describe_model(spec);
  const std::vector<std::string> prefixes = {"Table",     "eq.",     "derived",    "literature",
                                             "judgement", "section", "identified", "inferred",
                                             "default"};  // [thermal_network] defaults
  std::size_t numeric = 0;
  long previous_line = 0;
  for (const auto& row : rows) {
    EXPECT_GE(row.line, previous_line) << row.name << ": rows are not in file order";
    previous_line = row.line;
    if (!spec.params.count(row.name)) continue;
    ++numeric;
    EXPECT_FALSE(row.provenance.empty()) << row.name << " (line " << row.line << ")";
    const bool known = std::any_of(prefixes.begin(), prefixes.end(),
                                   [&](const auto& p) { return row.provenance.starts_with(p); });
    EXPECT_TRUE(known) << "models/mdma.toml:" << row.line << ": " << row.name << " has provenance '"
                       << row.provenance << "'";
  }
  EXPECT_EQ(numeric, spec.params.size());
}

TEST(ModelFile, DescribeListsOptionsAndStructure) {
  const auto rows = gmasim::describe_model(gmasim::builtin_model_spec());
  auto find = [&](const std::string& name) -> const gmasim::ParamRow* {
    for (const auto& r : rows)
      if (r.name == name) return &r;
    return nullptr;
  };
  const auto* opt = find("options.eq10_shape_law");
  ASSERT_NE(opt, nullptr);
  EXPECT_EQ(opt->value, "mean_field");
  EXPECT_EQ(opt->unit, "option");
  EXPECT_THAT(opt->provenance, StartsWith("judgement"));
  const auto* rods = find("stack.rods");
  ASSERT_NE(rods, nullptr);
  EXPECT_EQ(rods->value, "rod1, rod2, rod3");
  EXPECT_THAT(rods->provenance, StartsWith("section 2.1"));
  const auto* phi4 = find("circuit.branches.phi4");
  ASSERT_NE(phi4, nullptr);
  EXPECT_EQ(phi4->value, "0 -> A: R_shell + R_m + R_pm");
  EXPECT_THAT(phi4->provenance, HasSubstr("eq. 23 row 8"));
  const auto* phi1 = find("circuit.branches.phi1");
  ASSERT_NE(phi1, nullptr);
  EXPECT_EQ(phi1->value, "B -> E: rod rod1");
  const auto* chain = find("mechanics.chains.rod3");
  ASSERT_NE(chain, nullptr);
  EXPECT_EQ(chain->value, "s, dh");
  EXPECT_THAT(chain->provenance, StartsWith("eq. 18"));
  const auto* ms = find("material.Ms_A_per_m");
  ASSERT_NE(ms, nullptr);
  EXPECT_EQ(ms->value,
            fmt::format("{:g}", gmasim::builtin_model_spec().get("material.Ms_A_per_m")));
  EXPECT_EQ(ms->unit, "A/m");
}

TEST(ModelFile, ProvenanceIgnoresHashInsideStrings) {
  const auto spec = gmasim::parse_model_spec(
      replace_once(builtin_text(), "name = \"MDMA\"  # the prototype of section 4.1",
                   "name = \"MD#MA\"  # the 'real' # prototype"),
      "hash.toml");
  EXPECT_EQ(spec.meta.at("meta.name"), "MD#MA");
}

TEST(ModelFile, LoadFromFileUsesPathAsSource) {
  TempDir dir;
  const std::string path = dir.write("m.toml", builtin_text());
  const auto spec = gmasim::load_model_spec(path);
  EXPECT_EQ(spec.source, path);
  // describe_model re-reads the file for the comments of options and structure rows.
  const auto rows = gmasim::describe_model(spec);
  for (const auto& r : rows) {
    if (r.name == "stack.rods") {
      EXPECT_THAT(r.provenance, StartsWith("section 2.1"));
    }
  }
}

// =======================================================================================
// ModelSpec::get / set / line_of
// =======================================================================================
// Issue 19, item 9: a dimensional key must carry its unit suffix; without it the name is
// refused with the suffixed name suggested (it used to resolve, and `--set rod1.length=50` read
// 50 m unseen). A dimensionless key's own name needs no suffix; an unambiguous abbreviation of a
// dimensionless key ("material.lambda" for lambda_s) still resolves.
TEST(ModelSpecAccess, GetExactNamesAndRefuseUnitlessDimensionalKeys) {
  const auto spec = fixture_spec();
  EXPECT_EQ(spec.get("rod1.ja.k0_A_per_m"), 3032.0);
  EXPECT_EQ(spec.get("material.Ms_A_per_m"), 7.65e5);
  EXPECT_EQ(spec.get("mechanics.sleeves.t1.A2_m2"), 27.178e-6);
  EXPECT_EQ(spec.get("circuit.reluctances_per_H.R_pm"), 1.88e6);
  EXPECT_EQ(spec.get("material.lambda"), spec.get("material.lambda_s"));
  EXPECT_EQ(spec.get("material.chi_m"), 19.84);
  EXPECT_THAT(input_error([&] { (void)spec.get("rod1.ja.k0"); }),
              HasSubstr("parameter 'rod1.ja.k0' has a unit: write 'rod1.ja.k0_A_per_m' (the "
                        "value in A/m)"));
  EXPECT_THAT(input_error([&] { (void)spec.get("material.Ms"); }),
              HasSubstr("write 'material.Ms_A_per_m'"));
  auto changed = spec;
  EXPECT_THAT(input_error([&] { changed.set("rod1.length", 50.0); }),
              HasSubstr("write 'rod1.length_m' (the value in m)"));
  EXPECT_EQ(changed.get("rod1.length_m"), 0.030);  // unchanged
  EXPECT_EQ(spec.line_of("rod1.ja.k0_A_per_m"), line_of(builtin_text(), "k0_A_per_m = 3032.0"));
  EXPECT_EQ(spec.line_of("options.stress_sign"), line_of(builtin_text(), "stress_sign = "));
  EXPECT_EQ(spec.line_of("no.such.thing"), 0);
}

TEST(ModelSpecAccess, SetChangesOnlyTheValue) {
  auto spec = fixture_spec();
  spec.set("rod2.ja.k0_A_per_m", 5000.0);
  const auto& pv = spec.params.at("rod2.ja.k0_A_per_m");
  EXPECT_EQ(pv.value, 5000.0);
  EXPECT_EQ(spec.unit_of("rod2.ja.k0_A_per_m"), "A/m");
  EXPECT_EQ(pv.provenance, "Table 4");
  spec.set("preload.force_N", 0.0);
  EXPECT_EQ(spec.get("preload.force_N"), 0.0);
}

TEST(ModelSpecAccess, UnknownParameter) {
  auto spec = fixture_spec();
  const auto msg = input_error([&] { (void)spec.get("rod1.ja.kk"); });
  EXPECT_THAT(msg, HasSubstr("unknown parameter 'rod1.ja.kk'; known parameters start with "
                             "rod1.ja.: rod1.ja.a0_A_per_m"));
  const auto msg2 = input_error([&] { spec.set("bogus", 1.0); });
  EXPECT_THAT(msg2, HasSubstr("unknown parameter 'bogus'; known parameters start with "));
  EXPECT_THAT(msg2, HasSubstr("material."));
  // A prefix must be followed by '_' and match one key: "rod1.ja.beta" matches none.
  EXPECT_THAT(input_error([&] { (void)spec.get("rod1.ja.beta"); }),
              HasSubstr("unknown parameter 'rod1.ja.beta'"));
}

TEST(ModelSpecAccess, AmbiguousPrefix) {
  const auto spec = fixture_spec();
  // "rod1.k" is a prefix of neither key by itself: k_f and k_j both start with "rod1.k_".
  const auto msg = input_error([&] { (void)spec.get("rod1.k"); });
  EXPECT_THAT(msg, HasSubstr("ambiguous parameter 'rod1.k': matches rod1.k_f, rod1.k_j"));
}

TEST(ModelSpecAccess, SetRejectsValuesBreakingTheRules) {
  auto spec = fixture_spec();
  EXPECT_THAT(input_error([&] { spec.set("rod1.length_m", -1.0); }),
              HasSubstr("rod1.length_m = -1 m: must be > 0"));
  EXPECT_EQ(spec.get("rod1.length_m"), 0.030);  // unchanged
  EXPECT_THAT(input_error([&] { spec.set("rod1.outer_diameter_m", 0.01); }),
              HasSubstr("rod1.inner_diameter_m = 0.015 m: must be < rod1.outer_diameter_m"));
  EXPECT_EQ(spec.get("rod1.outer_diameter_m"), 0.020);
  EXPECT_THAT(input_error([&] { spec.set("material.Ms_A_per_m", std::nan("")); }),
              HasSubstr("NaN is not allowed"));
}

// model_toml / apply_assignments (issue 9, item 6): a changed model saves to a file that
// loads back with exactly its values, every other line untouched.
TEST(ModelWriter, SavedFileCarriesExactlyTheChangedValues) {
  const gmasim::ModelSpec base = gmasim::builtin_model_spec();
  const gmasim::ModelSpec changed = gmasim::apply_assignments(
      base, {"material.Ms_A_per_m=7.123456789012345e5", "rod2.ja.k0_A_per_m = 2500",
             "options.magnetic_state=printed"});
  const std::string text = gmasim::model_toml(changed, "test");
  const gmasim::ModelSpec back = gmasim::parse_model_spec(text, "saved");
  for (const auto& [name, pv] : changed.params)
    EXPECT_EQ(back.params.at(name).value, pv.value) << name;
  EXPECT_EQ(back.options, changed.options);
  EXPECT_EQ(back.params.at("material.Ms_A_per_m").value, 7.123456789012345e5);
  EXPECT_THAT(back.params.at("rod2.ja.k0_A_per_m").provenance, StartsWith("set: test; was "));
  // Only the three changed lines differ.
  std::istringstream a(base.text), b(text);
  std::string la, lb;
  int differ = 0, lines = 0;
  while (std::getline(a, la) && std::getline(b, lb)) {
    ++lines;
    differ += la != lb;
  }
  EXPECT_EQ(differ, 3);
  EXPECT_GT(lines, 100);
  // An unchanged model saves to its own text.
  EXPECT_EQ(gmasim::model_toml(base, "test"), base.text);
}

TEST(ModelWriter, AssignmentsAreCheckedLikeTheFile) {
  const gmasim::ModelSpec base = gmasim::builtin_model_spec();
  auto fails = [&](const std::string& a, const std::string& what) {
    try {
      (void)gmasim::apply_assignments(base, {a});
      ADD_FAILURE() << a << " was accepted";
    } catch (const gmasim::InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(what)) << a;
    }
  };
  fails("material.Ms_A_per_m", "expected name=value");
  fails("=3", "expected name=value");
  fails("material.Ms_A_per_m=inf", "not a finite number");
  fails("material.Ms_A_per_m=1e400", "not a finite number");
  fails("material.Ms_A_per_m=7e5x", "not a finite number");
  fails("rod1.length_m=-0.01", "must be > 0");
  fails("nothing.here=1", "unknown parameter");
  fails("options.nothing=x", "has no option 'options.nothing'");
  fails("options.magnetic_state=a b", "one word");
}

TEST(ModelWriter, DefaultedKeysAreWrittenIntoTheirTable) {
  // [thermal_network] is absent from the built-in file: a changed default is saved in a new
  // table; a file that has the table gets the key below its header.
  const gmasim::ModelSpec base = gmasim::builtin_model_spec();
  EXPECT_EQ(base.params.at("thermal_network.coil_resistance_ohm").line, 0);
  const auto changed =
      gmasim::apply_assignments(base, {"thermal_network.coil_resistance_ohm=2.25"});
  const std::string text = gmasim::model_toml(changed, "test");
  EXPECT_THAT(text, HasSubstr("\n[thermal_network]  # added by: test\ncoil_resistance_ohm = 2.25"));
  const auto back = gmasim::parse_model_spec(text, "saved");
  EXPECT_EQ(back.params.at("thermal_network.coil_resistance_ohm").value, 2.25);
  EXPECT_GT(back.params.at("thermal_network.coil_resistance_ohm").line, 0);
  const auto again = gmasim::apply_assignments(back, {"thermal_network.coil_alpha_per_K=0.004"});
  const auto back2 = gmasim::parse_model_spec(gmasim::model_toml(again, "test"), "saved");
  EXPECT_EQ(back2.params.at("thermal_network.coil_alpha_per_K").value, 0.004);
  EXPECT_EQ(back2.params.at("thermal_network.coil_resistance_ohm").value, 2.25);
}

// The single-rod template (issue 9, item 7): only the tables one rod needs; the optional
// tables take their defaults, each with a "default:" provenance, and the model runs.
TEST(ModelFile, SingleRodTemplateNeedsNoDummyTables) {
  const std::string path = std::string(GMASIM_SOURCE_DIR) + "/models/single_rod.toml";
  const gmasim::ModelSpec spec = gmasim::load_model_spec(path);
  for (const char* table :
       {"[magnet]", "[thermal_expansion]", "[mechanics.sleeves", "[mechanics.sleeve_modulus]"})
    EXPECT_EQ(spec.text.find(std::string("\n") + table), std::string::npos) << table;
  for (const char* key : {"magnet.alpha_pm1_per_K", "thermal_expansion.rod_length_m",
                          "mechanics.sleeve_modulus.Et_Pa", "thermal_network.coil_alpha_per_K"}) {
    EXPECT_EQ(spec.params.at(key).line, 0) << key;
    EXPECT_THAT(spec.params.at(key).provenance, StartsWith("default:")) << key;
  }
  // Its [thermal_network] holds only the winding, from which the coil resistance is derived
  // (gmasim/model/derived.hpp): 1.7241e-8 ohm m x 500 turns x 0.08 m / (pi (0.6 mm)^2 / 4).
  EXPECT_THAT(spec.params.at("thermal_network.coil_resistance_ohm").provenance,
              StartsWith("derived:"));
  EXPECT_NEAR(spec.params.at("thermal_network.coil_resistance_ohm").value,
              1.7241e-8 * 500 * 0.08 / (std::numbers::pi * 0.0006 * 0.0006 / 4), 1e-12);
  const gmasim::Model m = gmasim::compile(spec);
  EXPECT_EQ(m.rod_count(), 1);
  EXPECT_TRUE(m.sleeves.empty());
  // eq. 21 with the defaults: the rod alone expands.
  EXPECT_DOUBLE_EQ(m.xT_rod_m_per_K, 12.9e-6 * 0.050);
  EXPECT_EQ(m.xT_magnetizer_m_per_K + m.xT_output_rod_m_per_K + m.xT_sleeve_m_per_K, 0.0);
  gmasim::SimulationSettings s;
  s.waveform = gmasim::biased_sine(8.0, 10.0, 0.0);
  const gmasim::Result r = gmasim::simulate(m, s);
  ASSERT_FALSE(r.diverged) << r.error;
  // Physical: the stroke stays below the saturation strain 3/2 lambda_s L (85 um) and the
  // flux density below mu0 (H + M_s).
  EXPECT_GT(r.metrics.stroke_um, 20.0);
  EXPECT_LT(r.metrics.stroke_um, 1.5 * 1.1392e-3 * 0.050 * 1e6);
  EXPECT_LT(r.metrics.B_pp_T, 1.2);
  // A saved change writes the missing table.
  const auto changed =
      gmasim::apply_assignments(spec, {"thermal_expansion.output_rod_length_m=0.02",
                                       "thermal_expansion.output_rod_alpha_per_K=12e-6"});
  const auto back = gmasim::parse_model_spec(gmasim::model_toml(changed, "test"), path);
  EXPECT_EQ(back.params.at("thermal_expansion.output_rod_length_m").value, 0.02);
  EXPECT_NEAR(gmasim::compile(back).xT_output_rod_m_per_K, 0.02 * 12e-6, 1e-20);
}
