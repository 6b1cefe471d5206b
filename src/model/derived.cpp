// Quantities derived from geometry and material (gmasim/model/derived.hpp).
#include "gmasim/model/derived.hpp"

#include <fmt/format.h>

#include <numbers>
#include <optional>

#include "gmasim/physics/magnetic.hpp"

namespace gmasim {

namespace {

bool overridden(const ParamValue& pv) { return pv.line > 0 || pv.assigned; }

double value_or(const ModelSpec& spec, const std::string& name, double fallback) {
  const auto it = spec.params.find(name);
  return it == spec.params.end() ? fallback : it->second.value;
}

// The winding of every branch that carries a coil (in series: one current), when its wire
// diameter and mean turn length are given: N, l_turn and the wire's section.
struct Winding {
  double turns = 0, turn_length_m = 0, wire_area_m2 = 0;
};
std::optional<Winding> winding(const ModelSpec& spec) {
  const double d = value_or(spec, "thermal_network.coil_wire_diameter_m", 0.0);
  const double l = value_or(spec, "thermal_network.coil_mean_turn_length_m", 0.0);
  if (!(d > 0) || !(l > 0)) return std::nullopt;
  double turns = 0.0;
  for (const auto& [name, pv] : spec.params)
    if (name.starts_with("circuit.branches.") && name.ends_with(".coil_turns")) turns += pv.value;
  if (!(turns > 0)) return std::nullopt;
  return Winding{turns, l, std::numbers::pi * d * d / 4.0};
}

void push(std::vector<DerivedQuantity>& out, const std::pair<const std::string, ParamValue>& p,
          double derived, std::string formula) {
  out.push_back({p.first, derived, std::move(formula), overridden(p.second), p.second.value});
}

// The winding's resistance at T_ref and the coil node's heat capacity (its copper's mass x
// specific heat), when the winding is given.
void coil_quantities(const ModelSpec& spec, std::vector<DerivedQuantity>& out) {
  const std::optional<Winding> w = winding(spec);
  if (!w) return;
  const double copper_m3 = w->turns * w->turn_length_m * w->wire_area_m2;
  const auto R = spec.params.find("thermal_network.coil_resistance_ohm");
  const double rho = value_or(spec, "thermal_network.coil_resistivity_ohm_m", 0.0);
  if (R != spec.params.end() && rho > 0)
    push(out, *R, rho * w->turns * w->turn_length_m / w->wire_area_m2,
         fmt::format("thermal_network.coil_resistivity_ohm_m {:g} ohm m x {:g} turns x "
                     "coil_mean_turn_length_m {:g} m / (pi coil_wire_diameter_m^2 / 4) {:.4g} m^2",
                     rho, w->turns, w->turn_length_m, w->wire_area_m2));
  const auto C = spec.params.find("thermal_network.coil_heat_capacity_J_per_K");
  const double density = value_or(spec, "thermal_network.coil_density_kg_per_m3", 0.0);
  const double cp = value_or(spec, "thermal_network.coil_specific_heat_J_per_kg_K", 0.0);
  if (C != spec.params.end() && density > 0 && cp > 0)
    push(out, *C, density * copper_m3 * cp,
         fmt::format("thermal_network.coil_density_kg_per_m3 {:g} kg/m^3 x copper {:.4g} m^3 "
                     "({:g} turns x {:g} m x {:.4g} m^2) x coil_specific_heat_J_per_kg_K {:g} "
                     "J/(kg K)",
                     density, copper_m3, w->turns, w->turn_length_m, w->wire_area_m2, cp));
}

// Each rod's mass: density x its volume. Keys a spec lacks (a file with problems still being
// collected by the loader) skip the rod rather than throw.
void rod_masses(const ModelSpec& spec, std::vector<DerivedQuantity>& out) {
  const auto density = spec.params.find("material.density_kg_per_m3");
  if (density == spec.params.end()) return;
  const double rho = density->second.value;
  for (const auto& rod : spec.rods) {
    const auto mass = spec.params.find(rod + ".mass_kg");
    const auto od = spec.params.find(rod + ".outer_diameter_m");
    const auto id = spec.params.find(rod + ".inner_diameter_m");
    const auto len = spec.params.find(rod + ".length_m");
    if (mass == spec.params.end() || od == spec.params.end() || id == spec.params.end() ||
        len == spec.params.end())
      continue;
    const double ro = 0.5 * od->second.value, ri = 0.5 * id->second.value;
    const double area = std::numbers::pi * (ro * ro - ri * ri);
    const double m = rho * area * len->second.value;
    out.push_back({mass->first, m,
                   fmt::format("material.density_kg_per_m3 {:g} kg/m^3 x pi (r_o^2 - r_i^2) "
                               "{:.4g} m^2 x {}.length_m {:g} m",
                               rho, area, rod, len->second.value),
                   overridden(mass->second), mass->second.value});
  }
}

// Each reluctance of [circuit.reluctance_geometry.<name>]: l / (mu0 mu_r A) (eq. 2's law for a
// part of constant permeability). Keys a spec lacks skip it (the loader reports them).
void reluctances(const ModelSpec& spec, std::vector<DerivedQuantity>& out) {
  for (const auto& name : spec.reluctance_geometry_names) {
    const std::string g = "circuit.reluctance_geometry." + name + ".";
    const auto R = spec.params.find("circuit.reluctances_per_H." + name);
    const auto l = spec.params.find(g + "length_m");
    const auto A = spec.params.find(g + "area_m2");
    const auto mu_r = spec.params.find(g + "relative_permeability");
    if (R == spec.params.end() || l == spec.params.end() || A == spec.params.end() ||
        mu_r == spec.params.end())
      continue;
    push(out, *R, physics::fixed_reluctance(l->second.value, mu_r->second.value, A->second.value),
         fmt::format("{}length_m {:g} m / (mu0 x relative_permeability {:g} x area_m2 {:g} m^2)", g,
                     l->second.value, mu_r->second.value, A->second.value));
  }
}

}  // namespace

std::vector<DerivedQuantity> derived_quantities(const ModelSpec& spec) {
  std::vector<DerivedQuantity> out;
  rod_masses(spec, out);
  coil_quantities(spec, out);
  reluctances(spec, out);
  return out;
}

std::vector<std::string> apply_derivations(ModelSpec& spec) {
  std::vector<std::string> names;
  for (const auto& d : derived_quantities(spec)) {
    if (d.overridden) continue;
    ParamValue& pv = spec.params.at(d.name);
    pv.value = d.derived;
    pv.provenance = fmt::format("derived: {} = {:.6g}", d.formula, d.derived);
    names.push_back(d.name);
  }
  return names;
}

}  // namespace gmasim
