// The Jiles-Atherton law (eq. 9-10) behind the magnetisation-law seam (gmasim/magnetisation/
// laws.hpp): its per-rod state is RodState::Mirr_A_per_m, its constants at temperature are
// RodConditions::ja (src/model/magnetisation/jiles_atherton.cpp: eq. 10 and the parameter
// rows of [<rod>.ja]). The physics is in gmasim/physics/jiles_atherton.hpp.
#pragma once

#include <cmath>

#include "gmasim/magnetisation/law_id.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/jiles_atherton.hpp"

namespace gmasim {

struct JilesAthertonLaw {
  static constexpr MagnetisationLaw id = MagnetisationLaw::JilesAtherton;

  // make_state: demagnetised, M_irr = 0 (RodState's default).
  static void init_state(const RodConditions&, RodState&) {}

  // The magnetisation at the end of a move of the field from r.H_A_per_m to H1, from the state
  // of r, without changing it (the consistent state's Newton iterates); dM_dH as ja_step's.
  static double trial(const RodConditions& rc, const RodState& r, double H1, double M_guess,
                      double* dM_dH) {
    double Mirr = r.Mirr_A_per_m, M = r.M_A_per_m;
    physics::ja_step(r.H_A_per_m, H1, rc.MsT_mag, rc.ja, Mirr, M, M_guess, dM_dH);
    return M;
  }
  // The same move, committed: r's M_irr and M at H1 (r.H_A_per_m is the caller's to set).
  static void commit(const RodConditions& rc, RodState& r, double H1, double M_guess,
                     double* dM_dH) {
    physics::ja_step(r.H_A_per_m, H1, rc.MsT_mag, rc.ja, r.Mirr_A_per_m, r.M_A_per_m, M_guess,
                     dM_dH);
  }

  // dM/dH with M_irr pinned (the small-signal FRF): c dM_an / (1 - alpha c dM_an).
  static double reversible_susceptibility(const RodConditions& rc, const RodState& r) {
    const double He = r.H_A_per_m + rc.ja.alpha * r.M_A_per_m;
    const double dMan = physics::anhysteretic_slope(He, rc.MsT_mag, rc.ja.a_A_per_m);
    return rc.ja.c * dMan / (1.0 - rc.ja.alpha * rc.ja.c * dMan);
  }

  // The ledgers (gmasim/model/energy.hpp): the dissipation density of the step from (H0, M0) to r's
  // state, and the stored energy density of r's state [J/m^3].
  static double step_dissipation(const RodConditions& rc, double H0, double M0, const RodState& r) {
    return physics::ja_step_dissipation(H0, M0, r.H_A_per_m, r.M_A_per_m, rc.MsT_mag, rc.ja);
  }
  static double stored_energy_density(const RodConditions& rc, const RodState& r) {
    const double Han = physics::anhysteretic_field(r.Mirr_A_per_m, rc.MsT_mag, rc.ja.a_A_per_m);
    return physics::ja_stored_energy_density(r.H_A_per_m, r.M_A_per_m, r.Mirr_A_per_m, Han,
                                             rc.MsT_mag, rc.ja);
  }

  // The RK4 reference (rk4_reference.cpp) integrates the law as an ODE in its variable q
  // (M_irr): M from (H, q), dq/dt from dH/dt, and the commit of the integrated q at H1 = r.H.
  static double ode_variable(const RodState& r) { return r.Mirr_A_per_m; }
  static double ode_magnetisation(const RodConditions& rc, const RodState&, double H, double q,
                                  double M_guess) {
    return physics::ja_total_magnetisation(H, q, M_guess, rc.MsT_mag, rc.ja);
  }
  static double ode_rate(const RodConditions& rc, double H, double M, double q, double dH_dt) {
    const double delta = dH_dt >= 0.0 ? 1.0 : -1.0;
    return physics::ja_irreversible_slope(H, M, q, delta, rc.MsT_mag, rc.ja) * dH_dt;
  }
  static void ode_commit(const RodConditions& rc, RodState& r, double q1, double M_guess) {
    r.Mirr_A_per_m = q1;
    r.M_A_per_m =
        physics::ja_total_magnetisation(r.H_A_per_m, r.Mirr_A_per_m, M_guess, rc.MsT_mag, rc.ja);
  }

  // The FRF's anhysteretic bias (settle_at_bias): the law reduced to its anhysteretic curve
  // (c = 1: M = M_an(H + alpha M)), its magnetisation there, and the state that holds it.
  static void reduce_to_anhysteretic(RodConditions& rc) { rc.ja.c = 1.0; }
  static double anhysteretic_magnetisation(const RodConditions& rc, const RodState& r) {
    physics::JaCoefficients anh = rc.ja;
    anh.c = 1.0;  // M = M_an(H + alpha M)
    return physics::ja_total_magnetisation(r.H_A_per_m, r.M_A_per_m, r.M_A_per_m, rc.MsT_mag, anh);
  }
  // Returns how far the law's state moved (|change of M_irr|) [A/m].
  static double hold_anhysteretic(const RodConditions&, RodState& r, double M) {
    const double moved = std::fabs(M - r.Mirr_A_per_m);
    r.Mirr_A_per_m = M;
    r.M_A_per_m = M;
    return moved;
  }
};

}  // namespace gmasim
