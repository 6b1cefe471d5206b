// Conditions: every temperature-dependent constant of the model at one temperature.
// Each law has a freeze switch (ablation): a frozen law sees T = T_ref.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string_view>

#include "gmasim/errors.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/mechanics.hpp"
#include "model/conditions_detail.hpp"

namespace gmasim {
using namespace physics;

Freeze parse_freeze(const std::vector<std::string>& names) {
  Freeze f;
  for (const auto& n : names) {
    const auto* sw = std::find_if(std::begin(kFreezeSwitches), std::end(kFreezeSwitches),
                                  [&](const FreezeSwitch& s) { return n == s.name; });
    if (sw == std::end(kFreezeSwitches))
      throw InputError(fmt::format("unknown law '{}' to freeze; known: {}", n, freeze_name_list()));
    f.*(sw->flag) = true;
  }
  return f;
}

std::vector<std::string> frozen_names(const Freeze& f) {
  std::vector<std::string> names;
  for (const auto& s : kFreezeSwitches)
    if (f.*(s.flag)) names.emplace_back(s.name);
  return names;
}

std::string freeze_name_list() {
  std::string list;
  for (const auto& s : kFreezeSwitches) list += (list.empty() ? "" : ", ") + std::string(s.name);
  return list;
}

namespace {

void check_temperature(const Model& m, double temperature_C) {
  if (!std::isfinite(temperature_C))
    throw InputError(fmt::format("temperature {} degC: must be a finite number", temperature_C));
  if (temperature_C < -kZeroCelsiusInK)
    throw InputError(
        fmt::format("temperature {} degC: below absolute zero (-273.15 degC)", temperature_C));
  if (temperature_C >= m.material.Tc_C)
    throw InputError(
        fmt::format("temperature {} degC: at or above the Curie temperature T_c = {} degC of {} "
                    "(material.Tc_C); the model holds only below T_c",
                    temperature_C, m.material.Tc_C, m.spec.source));
}

// The temperature offsets the laws see: T - T_r, or 0 for a frozen law (and for the
// geometry when thermal expansion of the geometry is off).
struct Offsets {
  double dT, dT_geom;
  double of(bool frozen) const { return frozen ? 0.0 : dT; }
};

// The factor 1 + alpha dT of thermal expansion: lengths and radii must stay > 0 (issue 19, item
// 11: a large alpha at a low temperature made "nodal matrix = 0" out of a negative length).
// `kind` is "rod" or "sleeve"; `key` the coefficient's parameter (a sleeve's: under its table).
double expansion_factor(double alpha_per_K, double dT, const char* kind, const std::string& name,
                        const char* key) {
  const double g = 1.0 + alpha_per_K * dT;
  if (!(g > 0.0))
    throw InputError(fmt::format(
        "at {:+g} K from the reference the thermal expansion of {} '{}' ({}{} = {:g} 1/K) "
        "makes its length {:g} times the reference: lengths must stay > 0",
        dT, kind, name, std::string_view(kind) == "sleeve" ? "mechanics.sleeves." + name + "." : "",
        key, alpha_per_K, g));
  return g;
}

// Eq. (19): the sleeves' stiffness at E_t^T, with expanded lengths and areas.
void sleeve_conditions(const Model& m, const Offsets& d, Conditions& c) {
  for (const auto& s : m.sleeves) {
    std::array<double, 3> l{}, a{};
    for (std::size_t i = 0; i < 3; ++i) {
      const double g = expansion_factor(s.alpha_thermal_per_K, d.dT_geom, "sleeve", s.name,
                                        "alpha_thermal_per_K");
      l[i] = expanded_length(s.lengths_m[i], s.alpha_thermal_per_K, d.dT_geom);
      a[i] = s.areas_m2[i] * g * g;
    }
    c.sleeve_stiffness_N_per_m.push_back(sleeve_stiffness(c.Et_Pa, l, a));
  }
}

// A rod's geometry at T (l^T, r^T, A^T) and its prestress.
void rod_geometry(const Model& m, const RodModel& rod, const Offsets& d, RodConditions& rc) {
  const double g = expansion_factor(m.material.alpha_thermal_per_K, d.dT_geom, "rod", rod.name,
                                    "material.alpha_thermal_per_K");
  rc.length_m = rod.length_m * g;
  rc.r_outer_m = 0.5 * rod.outer_diameter_m * g;
  rc.r_inner_m = 0.5 * rod.inner_diameter_m * g;
  rc.area_m2 = kPi * (rc.r_outer_m * rc.r_outer_m - rc.r_inner_m * rc.r_inner_m);
  rc.k_f = rod.k_f;
  rc.k_j = rod.k_j;
  const double sign = m.options.stress_sign == StressSign::CompressionNegative ? -1.0 : 1.0;
  rc.sigma_p_Pa = m.preload_N / rc.area_m2;
  rc.sigma_Pa = sign * rc.sigma_p_Pa;
}

// Eq. (3)-(6), (8), (10), (13) of one rod at T: saturation, stress terms, the Delta-E
// constants, the JA coefficients, the resistivity and the eddy geometry.
void rod_material(const Model& m, const RodModel& rod, const Conditions& c, const Offsets& d,
                  RodConditions& rc) {
  const auto& mat = m.material;
  const auto& fz = c.freeze;
  const std::string& src = m.spec.source;
  const double T = c.temperature_C;
  auto MsT = [&](bool frozen) {  // eq. (4)
    return saturation_magnetisation(mat.Ms_A_per_m, d.of(frozen), mat.Tc_C - m.T_ref_C,
                                    mat.x_exponent);
  };
  rc.MsT_mu = MsT(fz.permeability);
  rc.MsT_mag = MsT(fz.magnetisation);
  rc.MsT_E = MsT(fz.modulus);
  rc.Ms_strain_A_per_m =
      m.options.eq11_saturation == Eq11Saturation::Temperature ? rc.MsT_mag : mat.Ms_A_per_m;
  const double L0 = Lambda0(rc.sigma_Pa, mat.lambda_s, mat.sigma_lambda_Pa);  // eq. (6)
  rc.S_mu_J_per_m3 =
      stress_energy_term(rc.sigma_Pa, mat.lambda_s, L0, mat.beta_per_K, d.of(fz.permeability));
  const double S_E =
      stress_energy_term(rc.sigma_Pa, mat.lambda_s, L0, mat.beta_per_K, d.of(fz.modulus));
  rc.dE = delta_e_terms(mat.Es_Pa, mat.lambda_s, rc.sigma_Pa, mat.sigma_lambda_Pa, mat.beta_per_K,
                        d.of(fz.modulus), rc.MsT_E, mat.chi_m, S_E);
  // Eq. (3) must give a positive susceptibility at M = 0 (where it is smallest).
  const double inv_chi0 = inverse_susceptibility(0.0, mat.chi_m, rc.S_mu_J_per_m3, rc.MsT_mu);
  if (!(inv_chi0 > 0.0))
    throw InputError(
        fmt::format("{}: at {} degC the stress terms of eq. (3) exceed 1/chi_m in rod '{}' "
                    "(1/chi = {:.4g} at M = 0); check preload.force_N, material.lambda_s, "
                    "material.sigma_lambda_Pa, options.stress_sign",
                    src, T, rod.name, inv_chi0));
  // Consistent magnetic state: eq. (3)'s stress and temperature terms act in the magnetisation
  // law's effective field (magnetic.hpp, magnetoelastic_coupling); frozen with mu_G.
  rc.alpha_sigma = magnetoelastic_coupling(rc.S_mu_J_per_m3, rc.MsT_mu);
  // The magnetisation law's temperature laws (src/model/magnetisation/).
  const double T_law = fz.magnetisation ? m.T_ref_C : T;
  with_magnetisation_law(m.options.magnetisation_law,
                         [&](auto law) { decltype(law)::temperature_laws(m, rod, T_law, T, rc); });
  rc.rho_ohm_m =
      resistivity(mat.rho0_ohm_m, mat.drho_dT_ohm_m_per_K, d.of(fz.resistivity));  // eq. (8)
  if (!(rc.rho_ohm_m > 0))
    throw InputError(fmt::format("{}: eq. (8) gives a non-positive resistivity {} ohm m at {} degC",
                                 src, rc.rho_ohm_m, T));
  rc.eddy_geometry_s_m_per_H =
      m.options.eddy_law == EddyLaw::Classical
          ? classical_eddy_coefficient(rc.r_outer_m, rc.r_inner_m, rc.rho_ohm_m)
          : eddy_time_constant(1.0, rc.r_outer_m, rc.r_inner_m, rod.k_j, rc.rho_ohm_m);  // eq. (7)
  rc.series_reluctance_per_H = m.options.magnetic_state == MagneticState::Consistent
                                   ? joint_reluctance(rod.joint_gap_m, rc.area_m2)
                                   : 0.0;
  rc.joint_compliance_m_per_N =
      m.options.joint_mechanics == JointMechanics::Bonded
          ? joint_compliance(rod.joint_gap_m, rod.joint_modulus_Pa, rc.area_m2)
          : 0.0;
}

// Eq. (24)-(28): rod i's oscillator mass, damping and the fixed part of its load compliance,
// summed over its load chain.
void rod_chain(const Model& m, std::size_t i, const Conditions& c, RodConditions& rc) {
  double m_load = 0.0, inv_c = 0.0, inv_k_fixed = 0.0;
  rc.chain_rod_count = 0;
  rc.chain_rods.fill(-1);
  for (const auto& link : m.chains[i]) {
    const auto idx = static_cast<std::size_t>(link.index);
    switch (link.kind) {
      case ChainLink::Element:
        m_load += m.elements[idx].mass_kg;
        inv_c += 1.0 / m.elements[idx].damping_N_s_per_m;
        inv_k_fixed += 1.0 / m.elements[idx].stiffness_N_per_m;
        break;
      case ChainLink::Sleeve:
        m_load += m.sleeves[idx].mass_kg;
        inv_c += 1.0 / m.sleeves[idx].damping_N_s_per_m;
        inv_k_fixed += 1.0 / c.sleeve_stiffness_N_per_m[idx];
        break;
      case ChainLink::Rod:
        m_load += m.rods[idx].mass_kg;
        inv_c += 1.0 / m.rods[idx].damping_N_s_per_m;
        rc.chain_rods[static_cast<std::size_t>(rc.chain_rod_count++)] = link.index;
        break;
    }
  }
  rc.mass_osc_kg = oscillator_mass(m.rods[i].mass_kg, m_load);
  rc.momentum_mass_kg = 0.5 * m.rods[i].mass_kg + m_load;
  rc.damping_osc_N_s_per_m = m.rods[i].damping_N_s_per_m + 1.0 / inv_c;
  rc.fixed_compliance_m_per_N = inv_k_fixed;
}

}  // namespace

namespace model_detail {

Conditions conditions_at(const Model& m, double temperature_C, const Freeze& fz) {
  check_temperature(m, temperature_C);
  Conditions c;
  c.temperature_C = temperature_C;
  c.freeze = fz;
  const double Tr = m.T_ref_C;
  const double dT = temperature_C - Tr;
  const Offsets d{dT, (m.options.geometry_thermal_expansion && !fz.geometry) ? dT : 0.0};

  c.pm_scale = pm_mmf(1.0, m.alpha_pm1_per_K, m.alpha_pm2_per_K2, d.of(fz.pm_mmf));  // eq. (1)
  c.Et_Pa = sleeve_modulus(m.Et_Pa, m.dEt_dT_Pa_per_C, fz.sleeve_modulus ? Tr : temperature_C);
  if (!(c.Et_Pa > 0.0))
    throw InputError(fmt::format(
        "temperature {} degC: eq. (19) gives a non-positive sleeve modulus E_t^T = {} Pa",
        temperature_C, c.Et_Pa));
  sleeve_conditions(m, d, c);
  c.thermal_expansion_m = thermal_expansion(m.xT_rod_m_per_K, m.xT_magnetizer_m_per_K,
                                            m.xT_output_rod_m_per_K, m.xT_sleeve_m_per_K,
                                            fz.geometry ? 0.0 : dT);  // eq. (21)
  for (std::size_t i = 0; i < m.rods.size(); ++i) {
    RodConditions rc{};
    rod_geometry(m, m.rods[i], d, rc);
    rod_material(m, m.rods[i], c, d, rc);
    rod_chain(m, i, c, rc);
    rc.inv_area_per_m2 = 1.0 / rc.area_m2;
    rc.length_over_area_per_m = rc.length_m / rc.area_m2;
    rc.area_over_length_m = rc.area_m2 / rc.length_m;
    rc.inv_MsT_E_m_per_A = 1.0 / rc.MsT_E;
    rc.inv_Ms_strain_m_per_A = 1.0 / rc.Ms_strain_A_per_m;
    rc.inv_mass_osc_per_kg = 1.0 / rc.mass_osc_kg;
    rc.four_sigma_p_over_lambda_s_Pa = 4.0 * rc.sigma_p_Pa / m.material.lambda_s;
    c.rods.push_back(rc);
  }
  return c;
}

}  // namespace model_detail

// Where a law fails, the message also gives the range over which the model can be computed
// (issue 19, item 8): the user learns the limit, not only the law that broke.
Conditions make_conditions(const Model& m, double temperature_C, const Freeze& fz) {
  try {
    return model_detail::conditions_at(m, temperature_C, fz);
  } catch (const InputError& e) {
    if (!std::isfinite(temperature_C)) throw;
    const auto range = computable_range(m, fz);
    if (!range || (temperature_C >= range->min_C && temperature_C <= range->max_C)) throw;
    throw InputError(fmt::format(
        "temperature {:g} degC: outside the range where {} can be computed, {} (`gmasim model "
        "show` prints it); there: {}",
        temperature_C, m.spec.source, range_text(*range), e.what()));
  }
}

}  // namespace gmasim
