// Model-file validation: one test per bad input, checking file, line, value and rule in the
// message.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
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
