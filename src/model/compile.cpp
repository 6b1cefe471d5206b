// ModelSpec -> Model: cross-field checks and typed assembly.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/model.hpp"

namespace gmasim {
namespace {

struct Reader {
  const ModelSpec& spec;
  double num(const std::string& name) const { return spec.get(name); }
  double num_or_zero(const std::string& name) const {
    auto it = spec.params.find(name);
    return it == spec.params.end() ? 0.0 : it->second.value;
  }
  std::string opt(const std::string& name) const {
    auto it = spec.options.find("options." + name);
    if (it == spec.options.end())
      throw InputError(located(spec.source, 0, fmt::format("missing option 'options.{}'", name)));
    return it->second;
  }
  long opt_line(const std::string& name) const {
    auto it = spec.option_lines.find("options." + name);
    return it == spec.option_lines.end() ? 0 : it->second;
  }
  [[noreturn]] void fail(long line, const std::string& msg) const {
    throw InputError(located(spec.source, line, msg));
  }
  bool boolean(const std::string& name) const {
    const std::string v = opt(name);
    if (v == "true") return true;
    if (v == "false") return false;
    fail(opt_line(name), fmt::format("options.{} = '{}': must be true or false", name, v));
  }
};

Options read_options(const Reader& r) {
  Options o;
  const std::string ss = r.opt("stress_sign");
  if (ss == "compression_negative")
    o.stress_sign = StressSign::CompressionNegative;
  else if (ss == "compression_positive")
    o.stress_sign = StressSign::CompressionPositive;
  else
    r.fail(r.opt_line("stress_sign"),
           fmt::format(
               "options.stress_sign = '{}': must be compression_negative or compression_positive",
               ss));
  const std::string sc = r.opt("eq10_temperature_scale");
  if (sc == "room_referenced")
    o.eq10_scale = Eq10Scale::RoomReferenced;
  else if (sc == "kelvin")
    o.eq10_scale = Eq10Scale::Kelvin;
  else if (sc == "celsius")
    o.eq10_scale = Eq10Scale::Celsius;
  else
    r.fail(r.opt_line("eq10_temperature_scale"),
           fmt::format(
               "options.eq10_temperature_scale = '{}': must be room_referenced, kelvin or celsius",
               sc));
  const std::string sl = r.opt("eq10_shape_law");
  if (sl == "printed")
    o.shape_law = ShapeLaw::Printed;
  else if (sl == "mean_field")
    o.shape_law = ShapeLaw::MeanField;
  else
    r.fail(r.opt_line("eq10_shape_law"),
           fmt::format("options.eq10_shape_law = '{}': must be printed or mean_field", sl));
  // One reference temperature per reading (issue 7): a^T proportional to T vanishes at 0 K,
  // so Table 4's a0 can only be the T_ref value, and then k, alpha and c must be too.
  if (o.shape_law == ShapeLaw::MeanField && o.eq10_scale != Eq10Scale::RoomReferenced)
    r.fail(r.opt_line("eq10_shape_law"),
           fmt::format("options.eq10_shape_law = 'mean_field' with eq10_temperature_scale = "
                       "'{}': mixes reference temperatures (a^T = a0 T/T_ref takes Table 4 at "
                       "T_ref, '{}' takes k0, alpha0, c0 at {}); use eq10_temperature_scale = "
                       "'room_referenced' (docs/model.md)",
                       sc, sc, sc == "kelvin" ? "0 K" : "0 degC"));
  const std::string ms = r.opt("magnetic_state");
  if (ms == "printed")
    o.magnetic_state = MagneticState::Printed;
  else if (ms == "consistent")
    o.magnetic_state = MagneticState::Consistent;
  else
    r.fail(r.opt_line("magnetic_state"),
           fmt::format("options.magnetic_state = '{}': must be printed or consistent", ms));
  const std::string e11 = r.opt("eq11_saturation");
  if (e11 == "temperature")
    o.eq11_saturation = Eq11Saturation::Temperature;
  else if (e11 == "reference")
    o.eq11_saturation = Eq11Saturation::Reference;
  else
    r.fail(r.opt_line("eq11_saturation"),
           fmt::format("options.eq11_saturation = '{}': must be temperature or reference", e11));
  o.thermal_expansion_in_output = r.boolean("thermal_expansion_in_output");
  o.geometry_thermal_expansion = r.boolean("geometry_thermal_expansion");
  return o;
}

}  // namespace

Model compile(const ModelSpec& spec) {
  const Reader r{spec};
  Model m;
  m.spec = spec;
  m.options = read_options(r);

  auto& mat = m.material;
  mat.Ms_A_per_m = r.num("material.Ms_A_per_m");
  mat.lambda_s = r.num("material.lambda_s");
  mat.sigma_lambda_Pa = r.num("material.sigma_lambda_Pa");
  mat.Es_Pa = r.num("material.Es_Pa");
  mat.Tc_C = r.num("material.Tc_C");
  mat.rho0_ohm_m = r.num("material.rho0_ohm_m");
  mat.drho_dT_ohm_m_per_K = r.num("material.drho_dT_ohm_m_per_K");
  mat.beta_per_K = r.num("material.beta_per_K");
  mat.chi_m = r.num("material.chi_m");
  mat.x_exponent = r.num("material.x");
  mat.alpha_thermal_per_K = r.num("material.alpha_thermal_per_K");
  m.T_ref_C = r.num("reference.T_ref_C");
  if (!(mat.Tc_C > m.T_ref_C))
    r.fail(spec.line_of("material.Tc_C"),
           fmt::format("material.Tc_C = {} degC: the Curie temperature must exceed "
                       "reference.T_ref_C = {} degC",
                       mat.Tc_C, m.T_ref_C));
  m.preload_N = r.num("preload.force_N");
  m.alpha_pm1_per_K = r.num("magnet.alpha_pm1_per_K");
  m.alpha_pm2_per_K2 = r.num("magnet.alpha_pm2_per_K2");

  // Rods.
  if (spec.rods.empty()) r.fail(0, "stack.rods is empty: at least one rod is required");
  if (spec.rods.size() > 8) r.fail(0, "stack.rods lists more than 8 rods");
  for (const auto& name : spec.rods) {
    RodModel rod;
    rod.name = name;
    rod.length_m = r.num(name + ".length_m");
    rod.r_outer_m = 0.5 * r.num(name + ".outer_diameter_m");
    rod.r_inner_m = 0.5 * r.num(name + ".inner_diameter_m");
    if (!(rod.r_inner_m < rod.r_outer_m) || rod.r_inner_m < 0)
      r.fail(
          spec.line_of(name + ".inner_diameter_m"),
          fmt::format("{}.inner_diameter_m = {} m: must be >= 0 and below outer_diameter_m = {} m",
                      name, 2 * rod.r_inner_m, 2 * rod.r_outer_m));
    rod.mass_kg = r.num(name + ".mass_kg");
    rod.k_f = r.num(name + ".k_f");
    rod.k_j = r.num(name + ".k_j");
    rod.damping_N_s_per_m = r.num(name + ".damping_N_s_per_m");
    rod.ja = {r.num(name + ".ja.a0_A_per_m"), r.num(name + ".ja.alpha0"), r.num(name + ".ja.c0"),
              r.num(name + ".ja.k0_A_per_m"), r.num(name + ".ja.beta1"),  r.num(name + ".ja.beta2"),
              r.num(name + ".ja.beta3")};
    m.rods.push_back(rod);
  }
  auto rod_index = [&](const std::string& name) -> int {
    auto it = std::find(spec.rods.begin(), spec.rods.end(), name);
    return it == spec.rods.end() ? -1 : static_cast<int>(it - spec.rods.begin());
  };

  // Circuit.
  Circuit& c = m.circuit;
  c.reference_node = spec.reference_node;
  c.node_names = spec.nodes;
  for (const auto& n : spec.nodes)
    if (n == spec.reference_node)
      r.fail(spec.nodes_line,
             fmt::format("circuit.nodes lists the reference node '{}'; list only the others", n));
  auto node_index = [&](const std::string& name, const SpecBranch& b) -> int {
    if (name == spec.reference_node) return -1;
    auto it = std::find(spec.nodes.begin(), spec.nodes.end(), name);
    if (it == spec.nodes.end())
      r.fail(b.line, fmt::format("circuit branch '{}' names node '{}', which is neither in "
                                 "circuit.nodes nor the reference node '{}'",
                                 b.name, name, spec.reference_node));
    return static_cast<int>(it - spec.nodes.begin());
  };
  for (const auto& b : spec.branches) {
    CircuitBranch cb;
    cb.name = b.name;
    cb.from = node_index(b.from, b);
    cb.to = node_index(b.to, b);
    if (!b.rod.empty()) {
      cb.rod = rod_index(b.rod);
      if (cb.rod < 0)
        r.fail(b.line, fmt::format("circuit branch '{}' names rod '{}', which is not in stack.rods",
                                   b.name, b.rod));
    } else {
      for (const auto& s : b.series)
        cb.fixed_reluctance_per_H += r.num("circuit.reluctances_per_H." + s);
    }
    cb.coil_turns = r.num_or_zero("circuit.branches." + b.name + ".coil_turns");
    cb.pm_mmf_At = r.num_or_zero("circuit.branches." + b.name + ".pm_mmf_At");
    c.branches.push_back(cb);
  }
  finalize_circuit(c, m.rod_count(), spec.source);

  // Flux sensor.
  for (const auto& name : spec.flux_sensor_branches) {
    auto it = std::find_if(c.branches.begin(), c.branches.end(),
                           [&](const CircuitBranch& b) { return b.name == name; });
    if (it == c.branches.end())
      r.fail(0, fmt::format("sensor.flux_branches names unknown branch '{}'", name));
    if (it->rod < 0)
      r.fail(0, fmt::format("sensor.flux_branches: branch '{}' is not a rod branch; the coil's "
                            "flux density is the rod flux over the rod area",
                            name));
    m.flux_sensor_branches.push_back(static_cast<int>(it - c.branches.begin()));
  }
  if (m.flux_sensor_branches.empty()) r.fail(0, "sensor.flux_branches is empty");

  // Mechanics.
  for (const auto& e : spec.element_names) {
    const std::string p = "mechanics.elements." + e + ".";
    m.elements.push_back(
        {e, r.num(p + "mass_kg"), r.num(p + "stiffness_N_per_m"), r.num(p + "damping_N_s_per_m")});
  }
  if (spec.params.count("mechanics.output_stage.mass_kg")) {
    auto& os = m.output_stage;
    os.enabled = true;
    os.mass_kg = r.num("mechanics.output_stage.mass_kg");
    os.stiffness_N_per_m = r.num("mechanics.output_stage.stiffness_N_per_m");
    os.damping_N_s_per_m = r.num("mechanics.output_stage.damping_N_s_per_m");
  }
  {
    auto& n = m.thermal_network;
    const std::string p = "thermal_network.";
    n.coil_resistance_ohm = r.num(p + "coil_resistance_ohm");
    n.coil_alpha_per_K = r.num(p + "coil_alpha_per_K");
    n.coil_C_J_per_K = r.num(p + "coil_heat_capacity_J_per_K");
    double rod_mass_kg = 0.0;
    for (const auto& rod : m.rods) rod_mass_kg += rod.mass_kg;
    n.rods_C_J_per_K = r.num(p + "rod_specific_heat_J_per_kg_K") * rod_mass_kg;
    n.housing_C_J_per_K = r.num(p + "housing_heat_capacity_J_per_K");
    n.G_coil_rods_W_per_K = r.num(p + "coil_to_rods_W_per_K");
    n.G_coil_housing_W_per_K = r.num(p + "coil_to_housing_W_per_K");
    n.G_rods_housing_W_per_K = r.num(p + "rods_to_housing_W_per_K");
    n.G_housing_ambient_W_per_K = r.num(p + "housing_to_ambient_W_per_K");
  }
  m.Et_Pa = r.num("mechanics.sleeve_modulus.Et_Pa");
  m.dEt_dT_Pa_per_C = r.num("mechanics.sleeve_modulus.dEt_dT_Pa_per_C");
  for (const auto& s : spec.sleeve_names) {
    const std::string p = "mechanics.sleeves." + s + ".";
    SleeveModel sl;
    sl.name = s;
    sl.mass_kg = r.num(p + "mass_kg");
    sl.damping_N_s_per_m = r.num(p + "damping_N_s_per_m");
    sl.alpha_thermal_per_K = r.num(p + "alpha_thermal_per_K");
    sl.lengths_m = {r.num(p + "l1_m"), r.num(p + "l2_m"), r.num(p + "l3_m")};
    sl.areas_m2 = {r.num(p + "A1_m2"), r.num(p + "A2_m2"), r.num(p + "A3_m2")};
    m.sleeves.push_back(sl);
  }
  m.chains.resize(m.rods.size());
  for (std::size_t i = 0; i < m.rods.size(); ++i) {
    auto it = spec.chains.find(m.rods[i].name);
    if (it == spec.chains.end())
      r.fail(0, fmt::format("mechanics.chains has no entry for rod '{}'", m.rods[i].name));
    for (const auto& name : it->second) {
      ChainLink link{ChainLink::Element, -1};
      auto e = std::find_if(m.elements.begin(), m.elements.end(),
                            [&](auto& x) { return x.name == name; });
      auto s =
          std::find_if(m.sleeves.begin(), m.sleeves.end(), [&](auto& x) { return x.name == name; });
      if (e != m.elements.end())
        link = {ChainLink::Element, static_cast<int>(e - m.elements.begin())};
      else if (s != m.sleeves.end())
        link = {ChainLink::Sleeve, static_cast<int>(s - m.sleeves.begin())};
      else if (rod_index(name) >= 0)
        link = {ChainLink::Rod, rod_index(name)};
      else
        r.fail(0, fmt::format("mechanics.chains.{} names '{}', which is no element, sleeve or rod",
                              m.rods[i].name, name));
      if (link.kind == ChainLink::Rod && link.index == static_cast<int>(i))
        r.fail(0, fmt::format("mechanics.chains.{} contains the rod itself", m.rods[i].name));
      m.chains[i].push_back(link);
    }
    if (m.chains[i].empty())
      r.fail(0, fmt::format("mechanics.chains.{} is empty: the rod needs a load path (eq. 18)",
                            m.rods[i].name));
  }

  // Eq. (21) products.
  // rod_length_m = 0 (the default when [thermal_expansion] is absent): the longest rod.
  double rod_length_m = r.num("thermal_expansion.rod_length_m");
  if (rod_length_m == 0.0)
    for (const auto& rod : m.rods) rod_length_m = std::max(rod_length_m, rod.length_m);
  m.xT_rod_m_per_K = mat.alpha_thermal_per_K * rod_length_m;
  m.xT_magnetizer_m_per_K = r.num("thermal_expansion.magnetizer_alpha_per_K") *
                            r.num("thermal_expansion.magnetizer_length_m");
  m.xT_output_rod_m_per_K = r.num("thermal_expansion.output_rod_alpha_per_K") *
                            r.num("thermal_expansion.output_rod_length_m");
  m.xT_sleeve_m_per_K =
      r.num("thermal_expansion.sleeve_alpha_per_K") * r.num("thermal_expansion.sleeve_length_m");
  return m;
}

}  // namespace gmasim
