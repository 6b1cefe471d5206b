// The Jiles-Atherton law (eq. 9-10) behind the magnetisation-law seam (gmasim/magnetisation/
// laws.hpp): its per-rod state is RodState::Mirr_A_per_m, its constants at temperature are
// RodConditions::ja (src/model/magnetisation/jiles_atherton.cpp: eq. 10 and the parameter
// rows of [<rod>.ja]). The physics is in gmasim/physics/jiles_atherton.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "gmasim/magnetisation/law_id.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/jiles_atherton.hpp"

namespace gmasim {

struct JilesAthertonLaw {
  static constexpr MagnetisationLaw id = MagnetisationLaw::JilesAtherton;

  // Its temperature laws (src/model/magnetisation/jiles_atherton.cpp): the law's constants of rod
  // `rod` at T_law_C (T_ref when frozen) into rc, given rc's M_s^T (MsT_mag) and eq. (3)'s coupling
  // (alpha_sigma); InputError naming the rod and the operating temperature T_C where the law
  // is not defined.
  static void temperature_laws(const Model& m, const RodModel& rod, double T_law_C, double T_C,
                               RodConditions& rc);
  // It has a lane kernel (src/lanes/): gmasim::lanes_supported asks the law, not a list.
  static constexpr bool has_lanes = true;

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
  // The consistent state's Newton solve tries several end fields H1 of one move: begin_move
  // fixes what depends on the move's start only (H_e0 and M_an(H_e0)), trial_from returns M, the
  // slope dM/dH and the state the move would leave at H1, and commit_trial commits that trial
  // as it is (the last Newton iterate; no second evaluation of the law). The move also carries
  // its last evaluation's exponentials: the next iterate is near and derives its own from them
  // (physics::JaExpPoints, exp_near), from the anchors the rod's last step left (RodState::ja_exp)
  // to the committed trial's, which keep them for the next step.
  // recent: the exponentials' last values in this move's Newton solve (physics::ja_evaluate),
  // none at its start: the later iterates take theirs from them (physics::exp_near).
  struct MoveStart : physics::JaMoveStart {
    physics::JaExpPoints near;
    physics::JaExpPoints recent;
  };
  struct Trial {
    double M, dM_dH, Mirr;
  };
  // The move starts where the law's last evaluation left the Langevin function, when it is
  // near (RodState::an_x; physics::ja_move_start_near): the step's start is the last end.
  static MoveStart begin_move(const RodConditions& rc, const RodState& r) {
    return {physics::ja_move_start_near(r.H_A_per_m, r.M_A_per_m, rc.MsT_mag, rc.ja,
                                        rc.ja_inv_a_m_per_A, rc.ja_inv_k_m_per_A, r.an_x,
                                        {r.an_L, r.an_dL}),
            r.ja_exp, physics::no_ja_exp_points<double>()};
  }
  static Trial trial_from(const RodConditions& rc, const RodState& r, const MoveStart& st,
                          double H1, double M_guess) {
    Trial t{};
    double chi_e = 0.0;
    physics::ja_step_from(r.H_A_per_m, st, H1, rc.MsT_mag, rc.ja, r.Mirr_A_per_m, r.M_A_per_m,
                          M_guess, t.Mirr, t.M, chi_e);
    t.dM_dH = physics::ja_slope(chi_e, rc.ja);
    return t;
  }
  // The consistent state's joint Newton solve in (H, M): one evaluation of the law at the end
  // field H1 and the iterate M_iter (physics::ja_evaluate), no inner solve. JointTrial holds
  // the law's state there (M = F(M_iter), M_irr; what commit_trial commits), the slope dM/dH,
  // 1/mu_r = 1/(1 + dM/dH), the Newton-corrected magnetisation M_next = M_iter - g/(1 - alpha
  // chi_e) the circuit is linearised about, and whether eq. (9) holds at M_iter to its
  // tolerance (|g| <= 1e-12 M_s^T). At H1 == H0 nothing moves (ja_step_from): M = M_next = M0.
  // Where |g| > 1e-3 M_s^T (physics::ja_safeguard_residual: a poor guess, large or violent
  // steps) eq. (9) is solved at H1 by ja_step_from from the Newton-corrected guess, as before
  // the joint solve: M_next = M.
  struct JointTrial : Trial {
    double inv_mu_r, M_next;
    double an_x;                       // where the law was evaluated (H_e / a)
    physics::LangevinValue an_lv;      // L and L' there
    const physics::JaExpPoints* near;  // the move's anchors (its MoveStart's, which outlives it)
    bool converged;
  };
  static void joint_trial(const RodConditions& rc, const RodState& r, MoveStart& st, double H1,
                          double M_iter, JointTrial& t) {
    const physics::JaJointTrialT<double> j = physics::ja_joint_trial(
        r.H_A_per_m, r.Mirr_A_per_m, r.M_A_per_m, r.an_x, {r.an_L, r.an_dL}, rc.MsT_mag, rc.ja,
        static_cast<const physics::JaMoveStart&>(st), st.near, st.recent, H1, M_iter, true);
    t.M = j.M;
    t.dM_dH = j.dM_dH;
    t.Mirr = j.Mirr;
    t.inv_mu_r = j.inv_mu_r;
    t.M_next = j.M_next;
    t.an_x = j.an_x;
    t.an_lv = j.an_lv;
    t.near = &st.near;
    t.converged = j.converged;
  }
  static void commit_trial(const RodConditions&, RodState& r, const Trial& t) {
    r.Mirr_A_per_m = t.Mirr;
    r.M_A_per_m = t.M;
  }
  static void commit_trial(const RodConditions& rc, RodState& r, const JointTrial& t) {
    commit_trial(rc, r, static_cast<const Trial&>(t));
    r.an_x = t.an_x;
    r.an_L = t.an_lv.L;
    r.an_dL = t.an_lv.dL;
    r.ja_exp = *t.near;
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

  // The field excursion about a reversal that stays (nearly) reversible [A/m]: the FRF's
  // small-signal limit is 10 % of it. JA: c k / (1 - c) (eq. 9: the reversible range of M_irr
  // pinned); infinite when c >= 1.
  // The field the law's loop is shaped by, which a field-driven record must reach (identify's
  // check of a record's units): eq. (10)'s anhysteretic shape a^T.
  static constexpr const char* characteristic_field_name = "anhysteretic shape field a";
  static double characteristic_field_A_per_m(const RodConditions& rc) { return rc.ja.a_A_per_m; }
  // The parameter that sets the loop's width, which track's plant mismatches scale (k+/-).
  static constexpr const char* loop_width_key = "ja.k0_A_per_m";

  static double reversible_field_range(const RodConditions& rc) {
    if (!(rc.ja.c < 1.0)) return std::numeric_limits<double>::infinity();
    return rc.ja.c * rc.ja.k_A_per_m / (1.0 - rc.ja.c);
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
