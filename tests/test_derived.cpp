// Quantities derived from geometry and material (gmasim/model/derived.hpp, issue 39 item 1):
// against hand calculations, following a change of the geometry, and an explicit value kept as
// an override with the derived one reported beside it.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>

#include "gmasim/io/io.hpp"
#include "gmasim/model/derived.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/physics/magnetic.hpp"

using namespace gmasim;

namespace {

std::string template_path(const char* name) {
  return std::string(GMASIM_SOURCE_DIR) + "/models/" + name;
}

// rho pi (r_o^2 - r_i^2) l by hand.
double rod_mass_by_hand(double rho, double d_out, double d_in, double length) {
  return rho * std::numbers::pi * (d_out * d_out - d_in * d_in) / 4.0 * length;
}

bool has_warning_about(const Model& m, const std::string& what) {
  for (const auto& w : model_warnings(m))
    if (w.find(what) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(Derived, TemplateRodMassIsDensityTimesVolume) {
  const Model m = load_model(template_path("single_rod.toml"));
  // models/single_rod.toml: a solid 10 mm rod, 50 mm long, Terfenol-D at 9250 kg/m^3.
  EXPECT_DOUBLE_EQ(m.rods[0].mass_kg, rod_mass_by_hand(9250.0, 0.010, 0.0, 0.050));
  EXPECT_NEAR(m.rods[0].mass_kg, 0.036325, 1e-6);
  const ParamValue& pv = m.spec.params.at("rod.mass_kg");
  EXPECT_EQ(pv.line, 0);
  EXPECT_TRUE(pv.provenance.starts_with("derived: material.density_kg_per_m3 9250"))
      << pv.provenance;
  EXPECT_TRUE(model_warnings(m).empty());
}

TEST(Derived, AGeometryChangeMovesTheMass) {
  // The new user: a 12 mm rod of 80 mm (about 0.084 kg), and a denser material.
  ModelSpec spec = apply_assignments(load_model_spec(template_path("single_rod.toml")),
                                     {"rod.outer_diameter_m=0.012", "rod.length_m=0.08"});
  Model m = compile(spec);
  EXPECT_DOUBLE_EQ(m.rods[0].mass_kg, rod_mass_by_hand(9250.0, 0.012, 0.0, 0.08));
  EXPECT_NEAR(m.rods[0].mass_kg, 0.0837, 1e-4);
  spec.set("material.density_kg_per_m3", 9000.0);  // set in code: compile() derives again
  spec.set("rod.inner_diameter_m", 0.004);
  m = compile(spec);
  EXPECT_DOUBLE_EQ(m.rods[0].mass_kg, rod_mass_by_hand(9000.0, 0.012, 0.004, 0.08));
  // The mass reaches the dynamics: the rod's oscillator mass grows with it (eq. 24).
  const Model base = load_model(template_path("single_rod.toml"));
  EXPECT_GT(make_conditions(m, 20.0).rods[0].mass_osc_kg,
            make_conditions(base, 20.0).rods[0].mass_osc_kg);
}

TEST(Derived, AnExplicitValueIsAnOverrideReportedBesideTheDerivedOne) {
  // The MDMA's Table 6 masses are given: kept as they are (within 0.4 % of the geometry's).
  const Model mdma = load_model("");
  EXPECT_EQ(mdma.rods[0].mass_kg, 0.038);
  const auto d = derived_quantities(mdma.spec);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_TRUE(d[0].overridden);
  EXPECT_NEAR(d[0].derived, rod_mass_by_hand(9250.0, 0.020, 0.015, 0.030), 1e-15);
  EXPECT_NEAR(d[0].value / d[0].derived, 0.9963, 1e-4);
  EXPECT_FALSE(has_warning_about(mdma, "mass_kg"));
  // A --set of the mass is an override too: it stays when the geometry moves, and beyond 10 %
  // from the derived value it is warned about, naming both values.
  const ModelSpec spec = apply_assignments(load_model_spec(template_path("single_rod.toml")),
                                           {"rod.mass_kg=0.05", "rod.length_m=0.08"});
  const Model m = compile(spec);
  EXPECT_EQ(m.rods[0].mass_kg, 0.05);
  EXPECT_TRUE(has_warning_about(m, "rod.mass_kg = 0.05 kg overrides the 0.05812 kg"));
  EXPECT_TRUE(has_warning_about(m, "-14 %"));
}

TEST(Derived, ModelSaveKeepsADerivedValueDerivedAndAnOverrideExplicit) {
  const ModelSpec base = load_model_spec(template_path("single_rod.toml"));
  // A geometry change: the saved file does not freeze the mass; read back, it derives it again.
  const std::string a = model_toml(apply_assignments(base, {"rod.length_m=0.08"}), "test");
  EXPECT_EQ(a.find("\nmass_kg = "), a.find("\nmass_kg = 0.010"));  // only the elements' masses
  const Model ma = compile(parse_model_spec(a, "saved"));
  EXPECT_DOUBLE_EQ(ma.rods[0].mass_kg, rod_mass_by_hand(9250.0, 0.010, 0.0, 0.08));
  // An override: written under [rod], read back as the file's own value.
  const std::string b = model_toml(apply_assignments(base, {"rod.mass_kg=0.05"}), "test");
  const ModelSpec sb = parse_model_spec(b, "saved");
  EXPECT_EQ(sb.params.at("rod.mass_kg").value, 0.05);
  EXPECT_GT(sb.params.at("rod.mass_kg").line, 0);
}

TEST(Derived, ABadGeometryIsReportedAtItsOwnLineNotAtTheDerivedMass) {
  const ModelSpec base = load_model_spec(template_path("single_rod.toml"));
  std::string text = base.text;
  const auto at = text.find("length_m = 0.050");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 16, "length_m = -0.05");
  try {
    (void)parse_model_spec(text, "bad.toml");
    FAIL() << "a negative length was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("rod.length_m"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("mass_kg"), std::string::npos) << msg;
  }
}

TEST(Derived, CoilResistanceFollowsTheTurnsWhenTheWindingIsGiven) {
  // The user: 800 turns instead of the template's 500, the same winding.
  const ModelSpec base = load_model_spec(template_path("single_rod.toml"));
  const auto R = [](const ModelSpec& s) { return compile(s).thermal_network.coil_resistance_ohm; };
  const double per_turn = 1.7241e-8 * 0.08 / (std::numbers::pi * 0.0006 * 0.0006 / 4.0);
  EXPECT_NEAR(R(base), 500 * per_turn, 1e-12);
  EXPECT_NEAR(R(apply_assignments(base, {"circuit.branches.coil.coil_turns=800"})), 800 * per_turn,
              1e-12);
  // A thinner wire: R ~ 1/d^2.
  EXPECT_NEAR(R(apply_assignments(base, {"thermal_network.coil_wire_diameter_m=0.0003"})),
              4 * 500 * per_turn, 1e-11);
  // Without the winding (the MDMA, which gives no [thermal_network]) the resistance is an
  // input: its default, not derived.
  const Model mdma = load_model("");
  EXPECT_EQ(mdma.thermal_network.coil_resistance_ohm, 1.5);
  for (const auto& d : derived_quantities(mdma.spec))
    EXPECT_NE(d.name, "thermal_network.coil_resistance_ohm");
}

TEST(Derived, CoilHeatCapacityIsTheWindingsCopper) {
  // models/single_rod.toml: 500 turns of 0.6 mm wire, 80 mm mean turn; copper 8890 kg/m^3, 385
  // J/(kg K): 500 x 0.08 m x 2.827e-7 m^2 = 1.131e-5 m^3, 0.1005 kg, 38.71 J/K.
  const ModelSpec base = load_model_spec(template_path("single_rod.toml"));
  const auto C = [](const ModelSpec& s) { return compile(s).thermal_network.coil_C_J_per_K; };
  const double per_turn = 8890.0 * 0.08 * std::numbers::pi * 0.0006 * 0.0006 / 4.0 * 385.0;
  EXPECT_NEAR(C(base), 500 * per_turn, 1e-12);
  EXPECT_NEAR(C(base), 38.709, 1e-3);
  // It follows the turns and the wire, as the resistance does; a value given is an override.
  EXPECT_NEAR(C(apply_assignments(base, {"circuit.branches.coil.coil_turns=800"})), 800 * per_turn,
              1e-12);
  EXPECT_NEAR(C(apply_assignments(base, {"thermal_network.coil_wire_diameter_m=0.0012"})),
              4 * 500 * per_turn, 1e-11);
  const Model given =
      compile(apply_assignments(base, {"thermal_network.coil_heat_capacity_J_per_K=60"}));
  EXPECT_EQ(given.thermal_network.coil_C_J_per_K, 60.0);
  EXPECT_TRUE(has_warning_about(given, "coil_heat_capacity_J_per_K"));  // 60 vs 38.7: > 10 %
  // The MDMA gives no winding: its capacity stays the input (default 80 J/K).
  EXPECT_EQ(load_model("").thermal_network.coil_C_J_per_K, 80.0);
}

namespace {

// models/single_rod.toml with its leakage reluctance given by a geometry instead of a number:
// an air path of 20 mm over 3.183e-4 m^2 (R = l / (mu0 A) = 5.0e7 /H, the template's R_leak).
std::string single_rod_with_leak_geometry(const std::string& leak_table) {
  std::ifstream in(template_path("single_rod.toml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string leak = "R_leak = 5.0e7";
  const auto at = text.find(leak);
  EXPECT_NE(at, std::string::npos);
  text.erase(at, text.find('\n', at) - at + 1);  // the number goes; the geometry derives it
  const auto branches = text.find("[[circuit.branches]]");
  text.insert(branches, leak_table + "\n");
  return text;
}

const char* kLeakGeometry =
    "[circuit.reluctance_geometry.R_leak]  # the air around the rod\n"
    "length_m = 0.02  # test\n"
    "area_m2 = 3.183098861837907e-4  # test: 0.02 / (mu0 x 5e7 x 3.1831e-4) = 1\n"
    "relative_permeability = 1.0  # air\n";

}  // namespace

// A fixed reluctance by its geometry: derived as l / (mu0 mu_r A), in the branch that names it,
// followed by a --set of its length, an explicit value kept as an override, and saved as geometry.
TEST(Derived, AReluctanceFollowsItsGeometry) {
  const std::string text = single_rod_with_leak_geometry(kLeakGeometry);
  const ModelSpec spec = parse_model_spec(text, "leak_geometry.toml");
  const double by_hand = 0.02 / (physics::kMu0 * 1.0 * 3.183098861837907e-4);  // CODATA mu0
  EXPECT_NEAR(by_hand / 5.0e7, 1.0, 1e-9);  // the template's R_leak (CODATA mu0 vs 4 pi 1e-7)
  EXPECT_DOUBLE_EQ(spec.params.at("circuit.reluctances_per_H.R_leak").value, by_hand);
  EXPECT_TRUE(
      spec.params.at("circuit.reluctances_per_H.R_leak")
          .provenance.starts_with("derived: circuit.reluctance_geometry.R_leak.length_m 0.02 m"));
  const Model m = compile(spec);
  const Model original = load_model(template_path("single_rod.toml"));
  for (std::size_t b = 0; b < m.circuit.branches.size(); ++b)
    EXPECT_NEAR(m.circuit.branches[b].fixed_reluctance_per_H,
                original.circuit.branches[b].fixed_reluctance_per_H,
                1e-9 * original.circuit.branches[b].fixed_reluctance_per_H + 1e-12);
  // A longer path: the reluctance follows, and with it the compiled branch.
  const Model longer =
      compile(apply_assignments(spec, {"circuit.reluctance_geometry.R_leak.length_m=0.05"}));
  EXPECT_DOUBLE_EQ(longer.circuit.branches[2].fixed_reluctance_per_H, 2.5 * by_hand);
  // A value given beside the geometry overrides it and is warned about beyond 10 %.
  const Model given = compile(apply_assignments(spec, {"circuit.reluctances_per_H.R_leak=8e7"}));
  EXPECT_EQ(given.circuit.branches[2].fixed_reluctance_per_H, 8e7);
  EXPECT_TRUE(has_warning_about(given, "circuit.reluctances_per_H.R_leak"));
  // Saved after a --set of the length: the geometry is written, the reluctance derived again.
  const std::string saved = model_toml(
      apply_assignments(spec, {"circuit.reluctance_geometry.R_leak.length_m=0.05"}), "test");
  EXPECT_EQ(saved.find("R_leak ="), std::string::npos);
  EXPECT_DOUBLE_EQ(
      compile(parse_model_spec(saved, "saved")).circuit.branches[2].fixed_reluctance_per_H,
      2.5 * by_hand);
}

// A bad or missing geometry is reported at its own line, naming the key and the rule.
TEST(Derived, ABadReluctanceGeometryIsReportedAtItsLine) {
  const auto message = [](const std::string& table) {
    try {
      (void)parse_model_spec(single_rod_with_leak_geometry(table), "leak_geometry.toml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string negative = message(
      "[circuit.reluctance_geometry.R_leak]\nlength_m = -0.02\narea_m2 = 3e-4\n"
      "relative_permeability = 1.0\n");
  EXPECT_NE(negative.find("circuit.reluctance_geometry.R_leak.length_m = -0.02 m: must be > 0"),
            std::string::npos)
      << negative;
  EXPECT_NE(negative.find("leak_geometry.toml:"), std::string::npos) << negative;
  EXPECT_EQ(negative.find("reluctances_per_H"), std::string::npos) << negative;
  const std::string missing =
      message("[circuit.reluctance_geometry.R_leak]\nlength_m = 0.02\narea_m2 = 3e-4\n");
  EXPECT_NE(missing.find("relative_permeability"), std::string::npos) << missing;
  const std::string unknown = message(
      "[circuit.reluctance_geometry.R_leak]\nlength_m = 0.02\narea_m2 = 3e-4\n"
      "relative_permeability = 1.0\nmu = 2\n");
  EXPECT_NE(unknown.find("mu"), std::string::npos) << unknown;
}
