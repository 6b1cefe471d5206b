// Per-rod laws at a rod's present state, shared by the production step (step.cpp), the RK4
// reference (rk4_reference.cpp) and the small-signal linearisation (frf.cpp): one
// implementation of each law's use, so the integrators differ only in how they advance time
// and the linearisation differentiates exactly what step() evaluates.
#pragma once

#include <string>

#include "gmasim/errors.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/magnetostriction.hpp"
#include "gmasim/physics/mechanics.hpp"

namespace gmasim {

// Permeability of a rod at magnetisation M (eq. 3); throws on a non-physical value.
inline double rod_permeability(const RodConditions& rc, double chi_m, double M, double t,
                               const std::string& rod) {
  const double inv_chi =
      physics::inverse_susceptibility(M / rc.MsT_mu, chi_m, rc.S_mu_J_per_m3, rc.MsT_mu);
  if (!(inv_chi > 0.0) || !std::isfinite(inv_chi))
    throw DivergenceError(t, rod, "1/chi of eq. (3)", inv_chi, "permeability not positive");
  return physics::permeability(inv_chi);
}

// Sets r.mu_r from M (eq. 3) and returns the rod's reluctance (eq. 2).
inline double set_rod_permeability(const Model& m, std::size_t i, const RodConditions& rc,
                                   RodState& r, double M, double t) {
  const double mu = rod_permeability(rc, m.material.chi_m, M, t, m.rods[i].name);
  r.mu_r = mu / physics::kMu0;
  return physics::rod_reluctance(rc.length_m, mu, rc.area_m2);
}

// Static field of rod i from the solved circuit (eq. 7, first line); sets r.phi_Wb.
inline double rod_static_field(const Model& m, std::size_t i, const RodConditions& rc, RodState& r,
                               const CircuitWorkspace& ws) {
  r.phi_Wb = ws.phi[static_cast<std::size_t>(m.circuit.rod_branch[i])];
  return physics::static_field(r.phi_Wb, rc.k_f, r.mu_r * physics::kMu0, rc.area_m2);
}

// Magnetostriction, Delta-E modulus and force of a rod at its present M (eq. 11-14, 17).
// The reciprocals are RodConditions' (divided once); 1/E is eq. (13)'s bracket. Returns the
// rod's compliance 1/k_rod = (1/E) l / A (eq. 17), for the load stiffness of eq. (18).
inline double update_rod_mechanics(const Material& mat, const RodConditions& rc, RodState& r) {
  const physics::RodMechanics k = physics::rod_mechanics(
      r.M_A_per_m, rc.inv_MsT_E_m_per_A, rc.dE, rc.inv_Ms_strain_m_per_A, mat.lambda_s,
      rc.sigma_p_Pa, rc.four_sigma_p_over_lambda_s_Pa, rc.area_m2, rc.area_over_length_m,
      rc.length_over_area_per_m, rc.joint_compliance_m_per_N, r.prestress_exp);
  r.E_Pa = k.E_Pa;
  r.lambda = k.lambda;
  r.F_N = k.F_N;
  r.k_rod_N_per_m = k.k_rod_N_per_m;
  return k.compliance_m_per_N;
}

// Load stiffness of a rod (eq. 18): its fixed members plus the rods in its chain, whose
// present stiffness k_rod(j) gives.
template <class KRod>
double load_stiffness(const RodConditions& rc, KRod k_rod) {
  double inv_k = rc.fixed_compliance_m_per_N;
  for (int j = 0; j < rc.chain_rod_count; ++j)
    inv_k += 1.0 / k_rod(rc.chain_rods[static_cast<std::size_t>(j)]);
  return 1.0 / inv_k;
}
// The same from the rods' compliances 1/k_rod (inv_k_rod[j], divided once per rod and step).
inline double load_stiffness_from_compliances(const RodConditions& rc, const double* inv_k_rod) {
  return physics::chain_stiffness(rc.fixed_compliance_m_per_N, inv_k_rod, rc.chain_rods.data(),
                                  rc.chain_rod_count);
}
inline double load_stiffness(const RodConditions& rc, const State& s) {
  return load_stiffness(rc,
                        [&](int j) { return s.rods[static_cast<std::size_t>(j)].k_rod_N_per_m; });
}

}  // namespace gmasim
