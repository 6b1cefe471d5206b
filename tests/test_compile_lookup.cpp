// compile()'s lookups (issue 22, "Speed"): the indexed find_param_def (src/model/
// param_lookup.cpp) finds the row the table scan finds, and compile(ModelSpec&&), which moves the
// spec into the Model, gives the Model compile(const ModelSpec&) gives, number for number.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

using namespace gmasim;

namespace {

// The scan find_param_def did before its index: every group's path, then every row.
const ParamDef* scan_param_def(const ModelSpec& spec, std::string_view dotted) {
  const auto dot = dotted.rfind('.');
  if (dot == std::string_view::npos) return nullptr;
  const std::string_view table = dotted.substr(0, dot), key = dotted.substr(dot + 1);
  for (const auto& g : parameter_groups()) {
    const auto open = g.path.find('<');
    bool match = false;
    if (open == std::string_view::npos) {
      match = g.path == table;
    } else {
      const auto close = g.path.find('>', open);
      const std::string_view prefix = g.path.substr(0, open), suffix = g.path.substr(close + 1);
      if (table.size() > prefix.size() + suffix.size() && table.starts_with(prefix) &&
          table.ends_with(suffix)) {
        const std::string_view name =
            table.substr(prefix.size(), table.size() - prefix.size() - suffix.size());
        bool rod = false;
        for (const auto& r : spec.rods) rod = rod || r == name;
        match = name.find('.') == std::string_view::npos &&
                (g.path.substr(open, close - open + 1) != "<rod>" || rod);
      }
    }
    if (!match) continue;
    for (const auto& p : parameter_table())
      if (p.group == g.group && (p.key == key || (p.key == "*" && !key.empty()))) return &p;
    return nullptr;
  }
  return nullptr;
}

std::vector<std::string> model_files() {
  const std::string dir = std::string(GMASIM_SOURCE_DIR) + "/models/";
  return {dir + "mdma.toml", dir + "mdma_printed.toml", dir + "single_rod.toml",
          dir + "single_rod_preisach.toml", dir + "single_rod_printed.toml"};
}

// Every landed number of two Models, bit for bit (the rows' land functions read them).
void expect_same_numbers(Model& a, Model& b, const std::string& what) {
  ASSERT_EQ(a.rods.size(), b.rods.size()) << what;
  ASSERT_EQ(a.elements.size(), b.elements.size()) << what;
  ASSERT_EQ(a.sleeves.size(), b.sleeves.size()) << what;
  ASSERT_EQ(a.circuit.branches.size(), b.circuit.branches.size()) << what;
  for (const ParamDef& row : parameter_table()) {
    if (row.lands == nullptr) continue;
    std::size_t n = 1;
    if (row.group == Group::Rod || row.group == Group::RodJa || row.group == Group::RodPreisach)
      n = a.rods.size();
    if (row.group == Group::Element) n = a.elements.size();
    if (row.group == Group::Sleeve) n = a.sleeves.size();
    if (row.group == Group::Branch) n = a.circuit.branches.size();
    for (std::size_t i = 0; i < n; ++i) {
      const double x = row.lands(a, i), y = row.lands(b, i);
      EXPECT_EQ(0, std::memcmp(&x, &y, sizeof x)) << what << " " << row.lands_in << " " << i;
    }
  }
  auto same = [&](double x, double y, const char* name) {
    EXPECT_EQ(0, std::memcmp(&x, &y, sizeof x)) << what << " " << name;
  };
  same(a.preload_N, b.preload_N, "preload_N");
  same(a.thermal_network.rods_C_J_per_K, b.thermal_network.rods_C_J_per_K, "rods_C");
  same(a.xT_rod_m_per_K, b.xT_rod_m_per_K, "xT_rod");
  same(a.xT_sleeve_m_per_K, b.xT_sleeve_m_per_K, "xT_sleeve");
  for (std::size_t k = 0; k < a.circuit.branches.size(); ++k) {
    const auto &p = a.circuit.branches[k], &q = b.circuit.branches[k];
    EXPECT_EQ(p.name, q.name);
    EXPECT_EQ(p.from, q.from);
    EXPECT_EQ(p.to, q.to);
    EXPECT_EQ(p.rod, q.rod);
    same(p.fixed_reluctance_per_H, q.fixed_reluctance_per_H, "fixed_reluctance_per_H");
  }
  EXPECT_EQ(a.flux_sensor_branches, b.flux_sensor_branches) << what;
  ASSERT_EQ(a.chains.size(), b.chains.size()) << what;
  for (std::size_t r = 0; r < a.chains.size(); ++r) {
    ASSERT_EQ(a.chains[r].size(), b.chains[r].size()) << what;
    for (std::size_t k = 0; k < a.chains[r].size(); ++k) {
      EXPECT_EQ(a.chains[r][k].kind, b.chains[r][k].kind);
      EXPECT_EQ(a.chains[r][k].index, b.chains[r][k].index);
    }
  }
  EXPECT_EQ(a.sensor_mount.enabled, b.sensor_mount.enabled) << what;
  EXPECT_TRUE(a.options == b.options) << what;
  EXPECT_EQ(a.spec.params.size(), b.spec.params.size()) << what;
  EXPECT_EQ(a.spec.text, b.spec.text) << what;
}

}  // namespace

TEST(CompileLookup, IndexedRowIsTheScannedRow) {
  for (const auto& path : model_files()) {
    const ModelSpec spec = load_model_spec(path);
    std::vector<std::string> names;
    for (const auto& [name, pv] : spec.params) {
      names.push_back(name);
      names.push_back(name + "x");                           // unknown key of a known table
      names.push_back("rod9." + name);                       // no such rod
      names.push_back(name.substr(0, name.rfind('.')));      // the table alone
      names.push_back(name.substr(0, name.rfind('.') + 1));  // empty key
    }
    for (const char* odd :
         {"", ".", "rod1", "rod1.", "rod1.ja", "rod1.ja.k0_A_per_m", "rod1.preisach.Hc0_A_per_m",
          "circuit.reluctances_per_H.R_x", "circuit.branches.a.b.c", "mechanics.elements.m.mass_kg",
          "mechanics.elements.a.b.mass_kg", "stack.rods", "<rod>.length_m"})
      names.emplace_back(odd);
    for (const auto& name : names)
      EXPECT_EQ(find_param_def(spec, name), scan_param_def(spec, name)) << path << ": " << name;
  }
}

TEST(CompileLookup, MovedSpecGivesTheSameModelNumberForNumber) {
  for (const auto& path : model_files()) {
    ModelSpec spec = load_model_spec(path);
    // Numbers set as identify sets them (ModelSpec::set), where the rules allow.
    int changed = 0;
    for (const auto& [name, pv] : ModelSpec(spec).params) {
      try {
        spec.set(name, pv.value * 1.001);
        ++changed;
      } catch (const InputError&) {
      }
    }
    EXPECT_GT(changed, 20) << path;
    Model a = compile(spec);
    Model b = compile(ModelSpec(spec));
    expect_same_numbers(a, b, path);
    if (a.options.magnetisation_law != MagnetisationLaw::JilesAtherton) continue;
    SimulationSettings s;
    s.temperature_C = 30.0;
    s.waveform = biased_sine(6.0, 200.0);
    s.periods = 1;
    const Result ra = simulate(a, s), rb = simulate(b, s);
    ASSERT_EQ(ra.series.columns.size(), rb.series.columns.size());
    for (std::size_t c = 0; c < ra.series.columns.size(); ++c) {
      ASSERT_EQ(ra.series.columns[c].size(), rb.series.columns[c].size());
      EXPECT_EQ(0, std::memcmp(ra.series.columns[c].data(), rb.series.columns[c].data(),
                               ra.series.columns[c].size() * sizeof(double)))
          << path << " " << ra.series.names[c];
    }
  }
}

TEST(CompileLookup, MovedSpecKeepsEveryMessage) {
  ModelSpec spec = load_model_spec(model_files().front());
  spec.params.at("material.Ms_A_per_m").value = -1.0;
  std::string copied, moved;
  try {
    (void)compile(spec);
  } catch (const InputError& e) {
    copied = e.what();
  }
  try {
    (void)compile(ModelSpec(spec));
  } catch (const InputError& e) {
    moved = e.what();
  }
  EXPECT_NE(copied.find("material.Ms_A_per_m = -1 A/m: must be > 0"), std::string::npos) << copied;
  EXPECT_EQ(copied, moved);
}
