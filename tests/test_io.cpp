// Input and output: model-file validation (one test per bad input, checking file, line,
// value and rule in the message), waveform CSV, output files, ModelSpec accessors.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/io.hpp"
#include "gmasim/validate.hpp"

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

namespace {

// The loader tests edit a frozen copy of the MDMA model file (tests/data/model_fixture.toml),
// so that recalibrating models/mdma.toml does not move their expected lines and values.
std::string builtin_text() {
  std::ifstream in(std::string(GMASIM_SOURCE_DIR) + "/tests/data/model_fixture.toml");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_FALSE(ss.str().empty()) << "tests/data/model_fixture.toml is missing";
  return ss.str();
}
gmasim::ModelSpec fixture_spec() {
  return gmasim::parse_model_spec(builtin_text(),
                                  std::string(gmasim::kBuiltinModelName) + " (built-in)");
}

// Replaces the single occurrence of `from` (the test fails if it is not unique).
std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << "not found: " << from;
  if (pos == std::string::npos) return text;
  EXPECT_EQ(text.find(from, pos + 1), std::string::npos) << "not unique: " << from;
  return text.replace(pos, from.size(), to);
}

// 1-based line of the first occurrence of `needle` in `text`.
long line_of(const std::string& text, const std::string& needle) {
  const auto pos = text.find(needle);
  EXPECT_NE(pos, std::string::npos) << "not found: " << needle;
  if (pos == std::string::npos) return -1;
  return 1 +
         static_cast<long>(std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n'));
}

// The message of the InputError thrown by `f` (the test fails if none is thrown).
std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const gmasim::InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return "";
}

std::string parse_error(const std::string& text, const std::string& name = "bad.toml") {
  return input_error([&] { (void)gmasim::parse_model_spec(text, name); });
}

std::string at(const std::string& file, long line) {
  return file + ":" + std::to_string(line) + ": ";
}

class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    path_ = fs::path(::testing::TempDir()) /
            ("gmasim_test_io_" + std::to_string(::getpid()) + "_" + std::to_string(++counter));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  std::string write(const std::string& name, const std::string& content) const {
    const fs::path p = path_ / name;
    std::ofstream(p, std::ios::binary) << content;
    return p.string();
  }
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  fs::path path_;
};

}  // namespace

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
  EXPECT_EQ(k0.unit, "A/m");
  EXPECT_EQ(k0.provenance, "Table 4");
  EXPECT_EQ(k0.line, line_of(text, "k0_A_per_m = 3032.0"));
  EXPECT_EQ(spec.params.at("circuit.branches.phi4.coil_turns").value, 720.0);
  EXPECT_EQ(spec.params.at("circuit.branches.phi4.pm_mmf_At").unit, "A-turns");
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
  for (const auto& [name, unit] : expected) EXPECT_EQ(spec.params.at(name).unit, unit) << name;
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
// Bad model files: one test per case
// =======================================================================================
TEST(ModelFileErrors, MissingFile) {
  TempDir dir;
  const std::string path = (dir.path() / "nope.toml").string();
  const auto msg = input_error([&] { (void)gmasim::load_model_spec(path); });
  EXPECT_EQ(msg, path + ": cannot open model file (No such file or directory)");
}

TEST(ModelFileErrors, MalformedToml) {
  const std::string text =
      replace_once(builtin_text(), "k_j = 1.07  # Table 4", "k_j = = 1.07  # Table 4");
  const long line = line_of(text, "k_j = = 1.07");
  const auto msg = parse_error(text);
  EXPECT_THAT(msg, StartsWith("bad.toml:" + std::to_string(line) + ":"));
  EXPECT_THAT(msg, HasSubstr("TOML syntax error"));
}

TEST(ModelFileErrors, MalformedTomlFromFile) {
  TempDir dir;
  const std::string path = dir.write("broken.toml", "[meta]\nname = \"unterminated\n");
  const auto msg = input_error([&] { (void)gmasim::load_model_spec(path); });
  EXPECT_THAT(msg, StartsWith(path + ":2:"));
  EXPECT_THAT(msg, HasSubstr("TOML syntax error"));
}

TEST(ModelFileErrors, DuplicateKeyIsSyntaxError) {
  const std::string text =
      replace_once(builtin_text(), "k_f = 3.80  # Table 4", "k_f = 3.80  # Table 4\nk_f = 3.9");
  const auto msg = parse_error(text);
  EXPECT_THAT(msg, StartsWith("bad.toml:" + std::to_string(line_of(text, "k_f = 3.9")) + ":"));
  EXPECT_THAT(msg, HasSubstr("TOML syntax error"));
}

TEST(ModelFileErrors, UnknownKey) {
  const std::string text =
      replace_once(builtin_text(), "k_j = 1.07  # Table 4", "k_j = 1.07  # Table 4\ncolour = 3");
  const auto msg = parse_error(text);
  EXPECT_THAT(msg, StartsWith(at("bad.toml", line_of(text, "colour = 3"))));
  EXPECT_THAT(msg, HasSubstr("unknown key 'colour' in [rod1]; expected one of: "
                             "outer_diameter_m, inner_diameter_m, length_m"));
}

TEST(ModelFileErrors, UnknownTopLevelTable) {
  const std::string text = builtin_text() + "\n[rod4]\nlength_m = 0.03\n";
  const auto msg = parse_error(text);
  EXPECT_THAT(msg, StartsWith(at("bad.toml", line_of(text, "[rod4]"))));
  EXPECT_THAT(msg, HasSubstr("unknown key 'rod4' at the top level"));
}

TEST(ModelFileErrors, MissingKey) {
  const std::string text = replace_once(
      builtin_text(), "length_m = 0.030  # derived: k_2 = 90 N/um (Table 6) with E = 30 GPa\n", "");
  const auto msg = parse_error(text);
  EXPECT_EQ(msg, at("bad.toml", line_of(text, "[rod2]")) + "missing key 'length_m' in [rod2]");
}

TEST(ModelFileErrors, MissingTable) {
  const std::string text = replace_once(
      builtin_text(),
      "[preload]\nforce_N = 500.0  # judgement: disk-spring preload; 3.6 / 5.5 / 9.9 MPa in "
      "rods 1 / 2 / 3\n",
      "");
  EXPECT_EQ(parse_error(text), "bad.toml:1: missing table [preload]");
}

TEST(ModelFileErrors, MissingRodTable) {
  const std::string text = replace_once(builtin_text(), "rods = [\"rod1\", \"rod2\", \"rod3\"]",
                                        "rods = [\"rod1\", \"rod2\", \"rod3\", \"rod9\"]");
  const auto msg = parse_error(text);
  EXPECT_THAT(msg, HasSubstr(at("bad.toml", line_of(text, "rods = [")) +
                             "missing table [rod9] (named in stack.rods)"));
  EXPECT_THAT(msg, HasSubstr("missing key 'rod9' in [mechanics.chains]"));
}

TEST(ModelFileErrors, WrongType) {
  const std::string text = replace_once(builtin_text(), "mass_kg = 0.038  # Table 6: m_1",
                                        "mass_kg = \"0.038\"  # Table 6: m_1");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "mass_kg = \"0.038\"")) +
                                   "rod1.mass_kg: expected a number, got a string");
}

TEST(ModelFileErrors, NegativeLength) {
  const std::string text = replace_once(builtin_text(), "length_m = 0.030  # derived: k_2",
                                        "length_m = -0.03  # derived: k_2");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "length_m = -0.03")) +
                                   "rod2.length_m = -0.03 m: must be > 0");
}

TEST(ModelFileErrors, ZeroArea) {
  const std::string text = replace_once(builtin_text(), "A2_m2 = 27.178e-6", "A2_m2 = 0.0");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "A2_m2 = 0.0")) +
                                   "mechanics.sleeves.t1.A2_m2 = 0 m^2: must be > 0");
}

TEST(ModelFileErrors, NonPositiveRodMass) {
  const std::string text =
      replace_once(builtin_text(), "mass_kg = 0.0139  # Table 6: m_3", "mass_kg = 0  # x");
  EXPECT_EQ(parse_error(text),
            at("bad.toml", line_of(text, "mass_kg = 0  # x")) + "rod3.mass_kg = 0 kg: must be > 0");
}

TEST(ModelFileErrors, NonPositiveSleeveMass) {
  const std::string text =
      replace_once(builtin_text(), "mass_kg = 4.2e-3  # Table 6: m_t2", "mass_kg = -4.2e-3");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "mass_kg = -4.2e-3")) +
                                   "mechanics.sleeves.t2.mass_kg = -0.0042 kg: must be > 0");
}

TEST(ModelFileErrors, NegativeElementMass) {
  // An element may be massless (the disk spring is), but not negative.
  const std::string text =
      replace_once(builtin_text(), "mass_kg = 0.72e-3  # Table 6: m_M3", "mass_kg = -1e-3");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "mass_kg = -1e-3")) +
                                   "mechanics.elements.M3.mass_kg = -0.001 kg: must be >= 0");
}

TEST(ModelFileErrors, NonPositiveStiffness) {
  const std::string text =
      replace_once(builtin_text(), "stiffness_N_per_m = 0.29e6", "stiffness_N_per_m = -0.29e6");
  EXPECT_EQ(parse_error(text),
            at("bad.toml", line_of(text, "stiffness_N_per_m = -0.29e6")) +
                "mechanics.elements.dh.stiffness_N_per_m = -290000 N/m: must be > 0");
}

TEST(ModelFileErrors, NonPositiveReluctance) {
  const std::string text = replace_once(builtin_text(), "R_or = 1.50e3", "R_or = 0");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "R_or = 0")) +
                                   "circuit.reluctances_per_H.R_or = 0 1/H: must be > 0");
}

TEST(ModelFileErrors, NaN) {
  const std::string text = replace_once(builtin_text(), "Es_Pa = 110.0e9", "Es_Pa = nan");
  const auto msg = parse_error(text);
  EXPECT_THAT(
      msg, StartsWith(at("bad.toml", line_of(text, "Es_Pa = nan")) + "material.Es_Pa = nan Pa: "));
  EXPECT_THAT(msg, HasSubstr("NaN is not allowed"));
}

TEST(ModelFileErrors, Inf) {
  const std::string text = replace_once(builtin_text(), "alpha0 = -0.0330", "alpha0 = -inf");
  const auto msg = parse_error(text);
  EXPECT_THAT(
      msg, StartsWith(at("bad.toml", line_of(text, "alpha0 = -inf")) + "rod2.ja.alpha0 = -inf: "));
  EXPECT_THAT(msg, HasSubstr("Inf is not allowed"));
}

TEST(ModelFileErrors, BadOptionString) {
  const std::string text = replace_once(builtin_text(), "eq10_shape_law = \"mean_field\"",
                                        "eq10_shape_law = \"parabolic\"");
  EXPECT_EQ(parse_error(text),
            at("bad.toml", line_of(text, "eq10_shape_law = ")) +
                "options.eq10_shape_law = \"parabolic\": must be one of: printed, mean_field");
}

TEST(ModelFileErrors, BadOptionType) {
  const std::string text = replace_once(builtin_text(), "geometry_thermal_expansion = true",
                                        "geometry_thermal_expansion = \"yes\"");
  EXPECT_EQ(parse_error(text),
            at("bad.toml", line_of(text, "geometry_thermal_expansion = ")) +
                "options.geometry_thermal_expansion: expected a boolean (true or false), "
                "got a string");
}

TEST(ModelFileErrors, BranchNamesUnknownRod) {
  const std::string text = replace_once(builtin_text(), "rod = \"rod2\"", "rod = \"rod7\"");
  EXPECT_EQ(parse_error(text),
            at("bad.toml", line_of(text, "rod = \"rod7\"")) +
                "circuit branch 'phi2': rod = \"rod7\" names an unknown rod; stack.rods has: "
                "rod1, rod2, rod3");
}

TEST(ModelFileErrors, BranchNamesUnknownReluctance) {
  const std::string text = replace_once(builtin_text(), "series = [\"R_s21\", \"R_AG2\"]",
                                        "series = [\"R_s21\", \"R_AG9\"]");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "R_AG9")) +
                                   "circuit branch 'phi8': series names unknown reluctance "
                                   "'R_AG9' (not in [circuit.reluctances_per_H])");
}

TEST(ModelFileErrors, BranchWithBothSeriesAndRod) {
  const std::string text =
      replace_once(builtin_text(), "rod = \"rod3\"", "rod = \"rod3\"\nseries = [\"R_1\"]");
  const long header = line_of(text, "name = \"phi3\"") - 1;
  EXPECT_EQ(parse_error(text), at("bad.toml", header) +
                                   "circuit branch 'phi3': needs exactly one of 'series' "
                                   "(reluctance names) or 'rod' (a rod of stack.rods)");
}

TEST(ModelFileErrors, NegativeCoilTurns) {
  const std::string text =
      replace_once(builtin_text(), "coil_turns = 720.0", "coil_turns = -720.0");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "coil_turns = -720.0")) +
                                   "circuit.branches.phi4.coil_turns = -720 turns: must be >= 0");
}

TEST(ModelFileErrors, NodesListTheReferenceNode) {
  const std::string text =
      replace_once(builtin_text(), "nodes = [\"A\", ", "nodes = [\"0\", \"A\", ");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "nodes = [")) +
                                   "circuit.nodes: '0' is the reference node "
                                   "(circuit.reference_node); list only the other nodes");
}

TEST(ModelFileErrors, SensorNamesUnknownBranch) {
  const std::string text = replace_once(builtin_text(), "flux_branches = [\"phi1\", \"phi2\"",
                                        "flux_branches = [\"phi1\", \"phi22\"");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "flux_branches")) +
                                   "sensor.flux_branches: unknown branch 'phi22' (not a name "
                                   "in [[circuit.branches]])");
}

TEST(ModelFileErrors, ChainNamesUnknownMember) {
  const std::string text =
      replace_once(builtin_text(), "rod3 = [\"s\", \"dh\"]", "rod3 = [\"s\", \"dhh\"]");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "rod3 = [\"s\", \"dhh\"]")) +
                                   "mechanics.chains.rod3: unknown member 'dhh' (not a "
                                   "[mechanics.elements.*], [mechanics.sleeves.*] or a rod of "
                                   "stack.rods)");
}

TEST(ModelFileErrors, ChainMissingForRod) {
  const std::string text = replace_once(
      builtin_text(), "rod3 = [\"s\", \"dh\"]  # eq. 18, 27, 28: k_lr3, m_lr3, c_lr3\n", "");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "[mechanics.chains]")) +
                                   "missing key 'rod3' in [mechanics.chains]: every rod of "
                                   "stack.rods needs a load chain");
}

TEST(ModelFileErrors, InnerDiameterNotBelowOuter) {
  const std::string text =
      replace_once(builtin_text(), "inner_diameter_m = 0.009", "inner_diameter_m = 0.014");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "inner_diameter_m = 0.014")) +
                                   "rod2.inner_diameter_m = 0.014 m: must be < "
                                   "rod2.outer_diameter_m = 0.014 m");
}

TEST(ModelFileErrors, C0OutOfRange) {
  const std::string text = replace_once(builtin_text(), "c0 = 0.1636", "c0 = 1.0");
  EXPECT_EQ(parse_error(text),
            at("bad.toml", line_of(text, "c0 = 1.0")) + "rod3.ja.c0 = 1: must be in [0, 1)");
}

TEST(ModelFileErrors, CurieBelowReference) {
  const std::string text = replace_once(builtin_text(), "Tc_C = 380.0", "Tc_C = 10.0");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "Tc_C = 10.0")) +
                                   "material.Tc_C = 10 degC: must be > reference.T_ref_C = 20 "
                                   "degC");
}

TEST(ModelFileErrors, ReferenceBelowAbsoluteZero) {
  const std::string text = replace_once(builtin_text(), "T_ref_C = 20.0", "T_ref_C = -300");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "T_ref_C = -300")) +
                                   "reference.T_ref_C = -300 degC: must be > -273.15 degC "
                                   "(absolute zero)");
}

TEST(ModelFileErrors, NegativeThermalAlpha) {
  const std::string text =
      replace_once(builtin_text(), "sleeve_alpha_per_K = 17.2e-6", "sleeve_alpha_per_K = -17.2e-6");
  EXPECT_EQ(parse_error(text), at("bad.toml", line_of(text, "sleeve_alpha_per_K = -")) +
                                   "thermal_expansion.sleeve_alpha_per_K = -1.72e-05 1/K: must "
                                   "be >= 0");
}

TEST(ModelFileErrors, AllProblemsReportedOnePerLineInFileOrder) {
  std::string text = builtin_text();
  text = replace_once(text, "R_or = 1.50e3", "R_or = -1");
  text = replace_once(text, "Es_Pa = 110.0e9", "Es_Pa = 0");
  text = replace_once(text, "k_j = 1.07  # Table 4", "k_j = 1.07  # Table 4\nbogus = 1");
  TempDir dir;
  const std::string path = dir.write("many.toml", text);
  const auto msg = input_error([&] { (void)gmasim::load_model_spec(path); });
  std::vector<std::string> lines;
  std::istringstream in(msg);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 3u) << msg;
  EXPECT_THAT(lines[0], StartsWith(at(path, line_of(text, "Es_Pa = 0")) + "material.Es_Pa"));
  EXPECT_THAT(lines[1], StartsWith(at(path, line_of(text, "bogus = 1")) + "unknown key"));
  EXPECT_THAT(lines[2], StartsWith(at(path, line_of(text, "R_or = -1")) +
                                   "circuit.reluctances_per_H.R_or = -1 1/H"));
}

// =======================================================================================
// ModelSpec::get / set / line_of
// =======================================================================================
TEST(ModelSpecAccess, GetExactAndByPrefix) {
  const auto spec = fixture_spec();
  EXPECT_EQ(spec.get("rod1.ja.k0_A_per_m"), 3032.0);
  EXPECT_EQ(spec.get("rod1.ja.k0"), 3032.0);
  EXPECT_EQ(spec.get("material.Ms"), 7.65e5);
  EXPECT_EQ(spec.get("mechanics.sleeves.t1.A2"), 27.178e-6);
  EXPECT_EQ(spec.get("circuit.reluctances_per_H.R_pm"), 1.88e6);
  EXPECT_EQ(spec.line_of("rod1.ja.k0"), line_of(builtin_text(), "k0_A_per_m = 3032.0"));
  EXPECT_EQ(spec.line_of("options.stress_sign"), line_of(builtin_text(), "stress_sign = "));
  EXPECT_EQ(spec.line_of("no.such.thing"), 0);
}

TEST(ModelSpecAccess, SetChangesOnlyTheValue) {
  auto spec = fixture_spec();
  spec.set("rod2.ja.k0", 5000.0);
  const auto& pv = spec.params.at("rod2.ja.k0_A_per_m");
  EXPECT_EQ(pv.value, 5000.0);
  EXPECT_EQ(pv.unit, "A/m");
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
  EXPECT_THAT(input_error([&] { spec.set("rod1.length", -1.0); }),
              HasSubstr("rod1.length_m = -1 m: must be > 0"));
  EXPECT_EQ(spec.get("rod1.length_m"), 0.030);  // unchanged
  EXPECT_THAT(input_error([&] { spec.set("rod1.outer_diameter", 0.01); }),
              HasSubstr("rod1.inner_diameter_m = 0.015 m: must be < rod1.outer_diameter_m"));
  EXPECT_EQ(spec.get("rod1.outer_diameter_m"), 0.020);
  EXPECT_THAT(input_error([&] { spec.set("material.Ms", std::nan("")); }),
              HasSubstr("NaN is not allowed"));
}

// =======================================================================================
// Waveform CSV
// =======================================================================================
TEST(WaveformCsv, Loads) {
  TempDir dir;
  const auto path = dir.write("w.csv", "t_s,current_A\r\n0,0\r\n0.001, 1.5\r\n0.002,-2e-1\r\n");
  const auto w = gmasim::load_waveform_csv(path);
  EXPECT_EQ(w.kind, gmasim::WaveformKind::Table);
  EXPECT_EQ(w.table_source, path);
  EXPECT_EQ(w.table_t_s, (std::vector<double>{0.0, 0.001, 0.002}));
  EXPECT_EQ(w.table_current_A, (std::vector<double>{0.0, 1.5, -0.2}));
}

TEST(WaveformCsv, MissingFile) {
  TempDir dir;
  const auto path = (dir.path() / "none.csv").string();
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ": cannot open waveform file (No such file or directory)");
}

TEST(WaveformCsv, EmptyFile) {
  TempDir dir;
  const auto path = dir.write("e.csv", "");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }), path + ":1: empty file");
}

TEST(WaveformCsv, BadHeader) {
  TempDir dir;
  const auto path = dir.write("h.csv", "time,current\n0,1\n1,2\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":1: expected header 't_s,current_A', got 'time,current'");
}

TEST(WaveformCsv, NonNumericCell) {
  TempDir dir;
  const auto path = dir.write("n.csv", "t_s,current_A\n0,1\n0.001,abc\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":3: non-numeric cell 'abc' in column current_A");
}

TEST(WaveformCsv, WrongCellCount) {
  TempDir dir;
  const auto path = dir.write("c.csv", "t_s,current_A\n0,1,2\n0.001,1\n");
  EXPECT_THAT(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
              StartsWith(path + ":2: expected 2 cells"));
}

TEST(WaveformCsv, TimeDoesNotIncrease) {
  TempDir dir;
  const auto path = dir.write("t.csv", "t_s,current_A\n0.001,0\n0.003,1\n0.002,2\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":4: time 0.002 s does not increase (previous 0.003 s)");
}

TEST(WaveformCsv, RepeatedTime) {
  TempDir dir;
  const auto path = dir.write("r.csv", "t_s,current_A\n0,0\n0,1\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":3: time 0 s does not increase (previous 0 s)");
}

TEST(WaveformCsv, NaN) {
  TempDir dir;
  const auto path = dir.write("nan.csv", "t_s,current_A\n0,0\n0.001,nan\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":3: NaN in column current_A ('nan')");
}

TEST(WaveformCsv, Inf) {
  TempDir dir;
  const auto path = dir.write("inf.csv", "t_s,current_A\n0,0\ninf,1\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":3: Inf in column t_s ('inf')");
}

TEST(WaveformCsv, FewerThanTwoRows) {
  TempDir dir;
  const auto path = dir.write("one.csv", "t_s,current_A\n0,1\n");
  EXPECT_THAT(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
              StartsWith(path + ":2: needs at least 2 data rows, found 1"));
}

// =======================================================================================
// Output files
// =======================================================================================
TEST(Output, AtomicWriteLeavesNoTempFiles) {
  TempDir dir;
  const auto path = (dir.path() / "out.csv").string();
  gmasim::write_file_atomic(path, "first\n");
  gmasim::write_file_atomic(path, "second\n");
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "second\n");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"out.csv"}));
}

TEST(Output, AtomicWriteFailureNamesPathAndLeavesNothing) {
  TempDir dir;
  const auto path = (dir.path() / "missing_dir" / "out.csv").string();
  EXPECT_EQ(input_error([&] { gmasim::write_file_atomic(path, "x"); }),
            path + ": cannot write output (No such file or directory)");
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Output, EnsureOutputDirCreatesParents) {
  TempDir dir;
  const auto sub = (dir.path() / "a" / "b").string();
  gmasim::ensure_output_dir(sub);
  EXPECT_TRUE(fs::is_directory(sub));
  EXPECT_TRUE(fs::is_empty(sub));  // the writability probe is removed
}

TEST(Output, OutputDirNotWritable) {
  // Tests may run as root, so permissions cannot make a directory unwritable: use a
  // regular file as the parent.
  TempDir dir;
  const auto file = dir.write("plain_file", "x");
  const auto sub = file + "/sub";
  const auto msg = input_error([&] { gmasim::ensure_output_dir(sub); });
  EXPECT_THAT(msg, StartsWith(sub + ": output directory is not writable ("));
  EXPECT_THAT(msg, HasSubstr("Not a directory"));
}

TEST(Output, OutputDirIsARegularFile) {
  TempDir dir;
  const auto file = dir.write("plain_file", "x");
  EXPECT_THAT(input_error([&] { gmasim::ensure_output_dir(file); }),
              StartsWith(file + ": output directory is not writable ("));
}

TEST(Output, TimeseriesCsv) {
  gmasim::TimeSeries ts;
  ts.names = {"t_s", "y_um"};
  ts.columns = {{0.0, 1e-5}, {1.0 / 3.0, -2.5}};
  EXPECT_EQ(gmasim::timeseries_csv(ts), "t_s,y_um\n0,0.3333333333\n1e-05,-2.5\n");
}

TEST(Output, MetricsJson) {
  gmasim::Result r;
  r.dt_s = 5e-6;
  r.steps = 60000;
  r.wall_time_s = 0.25;
  r.has_metrics = true;
  r.metrics.stroke_um = 12.5;
  r.metrics.hysteresis_um = std::nan("");
  r.thermal_expansion_um = 0.0;
  r.quantities.push_back({"rod1_F_N", 3.0, 4.5, 9.0, -0.25});
  gmasim::SimulationSettings s;
  s.waveform = gmasim::Waveform{};
  gmasim::Model m;
  m.spec.source = "dir\\model \"x\".toml";
  const auto json = gmasim::metrics_json(r, s, m);
  EXPECT_THAT(json, HasSubstr("\"status\": \"ok\""));
  EXPECT_THAT(json, HasSubstr("\"error\": null"));
  EXPECT_THAT(json, HasSubstr("\"model\": \"dir\\\\model \\\"x\\\".toml\""));
  EXPECT_THAT(json, HasSubstr("\"kind\": \"biased_sine\""));
  EXPECT_THAT(json, HasSubstr("\"pp_A\": 8"));
  EXPECT_THAT(json, HasSubstr("\"dt_s\": 5e-06"));
  EXPECT_THAT(json, HasSubstr("\"steps\": 60000"));
  EXPECT_THAT(json, HasSubstr("\"stroke_um\": 12.5"));
  EXPECT_THAT(json, HasSubstr("\"hysteresis_um\": null"));  // JSON has no NaN
  EXPECT_THAT(json, HasSubstr("\"thermal_expansion_um\": 0"));
  EXPECT_THAT(json, HasSubstr("\"rod1_F_N\": {\n      \"rms\": 3,\n      \"peak\": 4.5"));

  r.diverged = true;
  r.has_metrics = false;
  r.error = "diverged at t = 0.1 s in rod1: H = inf (line\n2)";
  const auto bad = gmasim::metrics_json(r, s, m);
  EXPECT_THAT(bad, HasSubstr("\"status\": \"diverged\""));
  EXPECT_THAT(bad, HasSubstr("\"error\": \"diverged at t = 0.1 s in rod1: H = inf (line\\n2)\""));
  EXPECT_THAT(bad, Not(HasSubstr("\"metrics\"")));
}

// =======================================================================================
// Error helpers
// =======================================================================================
TEST(Errors, Located) {
  EXPECT_EQ(gmasim::located("m.toml", 12, "bad"), "m.toml:12: bad");
  EXPECT_EQ(gmasim::located("m.toml", 0, "bad"), "m.toml: bad");
}

TEST(Errors, DivergenceMessage) {
  const gmasim::DivergenceError e(0.0125, "rod2", "M_A_per_m", INFINITY, "not finite");
  EXPECT_STREQ(e.what(), "diverged at t = 0.012500000 s in rod2: M_A_per_m = inf (not finite)");
  EXPECT_EQ(e.rod, "rod2");
  EXPECT_EQ(e.time_s, 0.0125);
  const gmasim::DivergenceError f(1.5, "", "B_T", 7.0, "circuit matrix not positive definite");
  EXPECT_STREQ(f.what(),
               "diverged at t = 1.500000000 s: B_T = 7 (circuit matrix not positive definite)");
}

// ---------------------------------------------------------------------------------------
// The validation layer (gmasim/validate.hpp, issue 8)
// ---------------------------------------------------------------------------------------
TEST(Validate, CountsAreCheckedBeforeConversion) {
  using gmasim::checked_count;
  EXPECT_EQ(checked_count(3.4, 10, "n"), 3);
  EXPECT_EQ(checked_count(10.0, 10, "n"), 10);
  EXPECT_EQ(gmasim::checked_ceil_count(2.0000000001, 10, "n"), 2);  // 1e-9 slack
  EXPECT_EQ(gmasim::checked_ceil_count(2.01, 10, "n"), 3);
  EXPECT_EQ(input_error([] { checked_count(1e300, 1e6, "steps"); }),
            "steps = 1e+300: too many (limit 1e+06)");
  EXPECT_EQ(input_error([] { checked_count(-1.0, 1e6, "steps"); }), "steps = -1: must be >= 0");
  EXPECT_EQ(input_error([] { checked_count(std::nan(""), 1e6, "steps"); }),
            "steps = nan: not a finite count");
  EXPECT_EQ(input_error([] { checked_count(INFINITY, 1e6, "steps"); }),
            "steps = inf: not a finite count");
  EXPECT_EQ(input_error([] { gmasim::checked_ceil_count(INFINITY, 1e6, "n"); }),
            "n = inf: not a finite count");
  EXPECT_THAT(input_error([] { gmasim::checked_step_count(1e300, 1e-5, "run"); }),
              HasSubstr("too many (limit 2e+08)"));
  EXPECT_EQ(gmasim::checked_step_count(0.1, 1e-5, "run"), 10000);
}

TEST(Validate, RangesNameTheValueTheUnitAndTheRule) {
  EXPECT_EQ(input_error([] { gmasim::require_in(5.0, 0.0, 1.0, "x", "A"); }),
            "x = 5 A: must be in [0 A, 1 A]");
  EXPECT_EQ(input_error([] { gmasim::require_positive(0.0, "f", "Hz"); }), "f = 0 Hz: must be > 0");
  EXPECT_EQ(input_error([] { gmasim::require_finite(-INFINITY, "T", "degC"); }),
            "T = -inf degC: must be a finite number");
  EXPECT_EQ(input_error([] { gmasim::require_int_in(0, 1, 9, "islands"); }),
            "islands = 0: must be in [1, 9]");
}

TEST(Validate, LongMessagesAreClipped) {
  const std::string line(1'000'000, 'x');
  const gmasim::InputError e("bad value '" + line + "'");
  EXPECT_LE(std::string(e.what()).size(), gmasim::kMaxErrorChars + 100);
  EXPECT_THAT(e.what(), HasSubstr("characters omitted"));
  EXPECT_THAT(e.what(), StartsWith("bad value 'xxx"));
  EXPECT_EQ(gmasim::clip_for_message("short"), "short");
}

TEST(Validate, SimulationSettingsAreRefusedBeforeAnyWork) {
  const gmasim::Model m = gmasim::compile(fixture_spec());
  auto err = [&](auto edit) {
    gmasim::SimulationSettings s;
    edit(s);
    return input_error([&] { (void)gmasim::simulate(m, s); });
  };
  using S = gmasim::SimulationSettings;
  EXPECT_EQ(err([](S& s) { s.periods = 1e300; }), "periods = 1e+300: must be in [1, 1e+06]");
  EXPECT_THAT(err([](S& s) { s.waveform.frequency_Hz = 1e-300; }), HasSubstr("too many"));
  EXPECT_THAT(err([](S& s) { s.dt_s = 1e-300; }), HasSubstr("too many"));
  EXPECT_THAT(err([](S& s) { s.periods = 3000; }), HasSubstr("record less often"));
  EXPECT_EQ(err([](S& s) { s.temperature_C = std::nan(""); }),
            "temperature = nan degC: must be a finite number");
  EXPECT_EQ(err([](S& s) { s.duration_s = INFINITY; }),
            "duration = inf s: must be a finite number");
  EXPECT_EQ(err([](S& s) {
              s.waveform.kind = gmasim::WaveformKind::Step;
              s.waveform.step_time_s = std::nan("");
              s.duration_s = 0.01;
            }),
            "step time = nan s: must be a finite number");
  EXPECT_EQ(err([](S& s) {
              s.waveform.kind = gmasim::WaveformKind::Table;
              s.waveform.table_t_s = {100.0, 100.01};
              s.waveform.table_current_A = {1.0, 2.0};
            }),
            "waveform table: starts at t = 100 s; a waveform table must start at t = 0 (the "
            "run starts there): subtract 100 s from t_s");
  // 3000 periods recorded every 10th step are fine to validate (not run here).
  gmasim::SimulationSettings ok;
  ok.periods = 3000;
  ok.record_every = 10;
  EXPECT_NO_THROW(gmasim::validate(ok));
}

TEST(Output, NeverReplacesANonRegularFile) {
  TempDir dir;
  const auto link = dir.path() / "metrics.json";
  fs::create_symlink("/dev/null", link);
  EXPECT_THAT(input_error([&] { gmasim::write_file_atomic(link.string(), "x"); }),
              HasSubstr("the destination is a character device"));
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  fs::create_directory(dir.path() / "sub");
  EXPECT_THAT(input_error([&] { gmasim::write_file_atomic((dir.path() / "sub").string(), "x"); }),
              HasSubstr("the destination is a directory"));
}

TEST(Output, WriteFilesAtomicWritesAllOrNothing) {
  TempDir dir;
  const auto a = (dir.path() / "a.csv").string(), b = (dir.path() / "b.json").string();
  gmasim::write_files_atomic({{a, "A1"}, {b, "B1"}});
  // The second destination is refused: neither file changes, no temporary is left.
  fs::create_directory(dir.path() / "c");
  const auto c = (dir.path() / "c").string();
  EXPECT_THROW(gmasim::write_files_atomic({{a, "A2"}, {c, "C2"}}), gmasim::InputError);
  std::ifstream in(a);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "A1");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"a.csv", "b.json", "c"}));
}

TEST(Input, FilesLargerThanTheLimitAreRefused) {
  TempDir dir;
  const auto big = (dir.path() / "big.toml").string();
  {
    std::ofstream out(big);  // a sparse file just over the limit
  }
  fs::resize_file(big, gmasim::kMaxInputBytes + 1);
  EXPECT_THAT(input_error([&] { (void)gmasim::read_input_file(big, "model file"); }),
              HasSubstr("model file is larger than 256 MiB"));
}

TEST(Input, TomlGuardRefusesWhatTomlPlusPlusMishandles) {
  for (const char* text : {"[[[1]]]\n", "[[[a]]\n", "[[[]]\n", "[[=\n", "[&\n", "[\xCE\xA0]\n"})
    EXPECT_THAT(input_error([&] { (void)gmasim::parse_model_spec(text, "t.toml"); }),
                StartsWith("t.toml:1: malformed table header"))
        << text;
  EXPECT_THAT(input_error([] { (void)gmasim::parse_model_spec("\xCE\xA0 = 1\n", "t.toml"); }),
              StartsWith("t.toml:1: expected a key"));
  EXPECT_THAT(
      input_error([] { (void)gmasim::parse_model_spec(std::string("a = 1\n\0", 7), "t.toml"); }),
      StartsWith("t.toml:2: NUL byte"));
  // Brackets inside strings, comments and multi-line arrays are values, not headers.
  const std::string fine =
      "\xEF\xBB\xBF# [&\n[meta]\nname = \"[[=\"  # ]\nlist = [\n  [1, 2],\n  [\n  3],\n]\n"
      "s = '''\n[&\n'''\n";
  const std::string err = input_error([&] { (void)gmasim::parse_model_spec(fine, "t.toml"); });
  EXPECT_THAT(err, Not(HasSubstr("malformed")));
  EXPECT_THAT(err, Not(HasSubstr("expected a key")));
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
  for (const char* table : {"[magnet]", "[thermal_expansion]", "[mechanics.sleeves",
                            "[mechanics.sleeve_modulus]", "[thermal_network]"})
    EXPECT_EQ(spec.text.find(std::string("\n") + table), std::string::npos) << table;
  for (const char* key : {"magnet.alpha_pm1_per_K", "thermal_expansion.rod_length_m",
                          "mechanics.sleeve_modulus.Et_Pa", "thermal_network.coil_resistance_ohm"}) {
    EXPECT_EQ(spec.params.at(key).line, 0) << key;
    EXPECT_THAT(spec.params.at(key).provenance, StartsWith("default:")) << key;
  }
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
  const auto changed = gmasim::apply_assignments(spec, {"thermal_expansion.output_rod_length_m=0.02",
                                                       "thermal_expansion.output_rod_alpha_per_K=12e-6"});
  const auto back = gmasim::parse_model_spec(gmasim::model_toml(changed, "test"), path);
  EXPECT_EQ(back.params.at("thermal_expansion.output_rod_length_m").value, 0.02);
  EXPECT_NEAR(gmasim::compile(back).xT_output_rod_m_per_K, 0.02 * 12e-6, 1e-20);
}
