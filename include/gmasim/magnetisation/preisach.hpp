// The Preisach law behind the magnetisation-law seam (gmasim/magnetisation/laws.hpp;
// docs/model.md, "The Preisach law"): its per-rod state is RodState::preisach (the extrema
// stack, physics/preisach.hpp), its constants at temperature RodConditions::preisach
// (src/model/magnetisation/preisach.cpp: the temperature laws and the rows of
// [<rod>.preisach]).
#pragma once

#include "gmasim/magnetisation/law_id.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/preisach.hpp"

namespace gmasim {

struct PreisachLaw {
  static constexpr MagnetisationLaw id = MagnetisationLaw::Preisach;

  // Its temperature laws (src/model/magnetisation/preisach.cpp): the law's constants of rod `rod`
  // at T_law_C (T_ref when frozen) into rc, given rc's M_s^T (MsT_mag) and eq. (3)'s coupling
  // (alpha_sigma); InputError naming the rod and the operating temperature T_C where the law
  // is not defined.
  static void temperature_laws(const Model& m, const RodModel& rod, double T_law_C, double T_C,
                               RodConditions& rc);
  // It has a lane kernel (src/lanes/): gmasim::lanes_supported asks the law, not a list.
  static constexpr bool has_lanes = true;

  // make_state: AC-demagnetised at zero field (physics::preisach_demagnetise).
  static void init_state(const RodConditions& rc, RodState& r) {
    physics::preisach_demagnetise(rc.preisach.dist, r.preisach, 0.0);
  }

  // The move of the field from r.H_A_per_m to H1 (the history starts from its own x_now, so a
  // change of temperature, which rescales the reduced field, is part of the move).
  static double trial(const RodConditions& rc, const RodState& r, double H1, double M_guess,
                      double* dM_dH) {
    if (H1 == r.H_A_per_m) {
      if (dM_dH) *dM_dH = reversible_susceptibility(rc, r);
      return r.M_A_per_m;
    }
    return physics::preisach_magnetisation(H1, rc.MsT_mag, rc.preisach, r.preisach, M_guess, dM_dH,
                                           nullptr);
  }
  // The consistent state's Newton iterates (as JilesAthertonLaw's): the trial keeps the reduced
  // input x1 it reached, and commit_trial pushes it onto the history without evaluating the
  // distribution again.
  struct MoveStart {};
  struct Trial {
    double M, dM_dH, x1;
    bool moved;
    double mu, mc, mu_u;  // the up-switched measure at x1 and its moments, committed as they are
  };
  static MoveStart begin_move(const RodConditions&, const RodState&) { return {}; }
  static Trial trial_from(const RodConditions& rc, const RodState& r, const MoveStart&, double H1,
                          double M_guess) {
    // the law's trial, written once (physics::preisach_trial; the lanes run the same text)
    const physics::PreisachTrialT<double> p =
        physics::preisach_trial(physics::preisach_constants(rc.MsT_mag, rc.preisach), &r.preisach,
                                r.H_A_per_m, r.M_A_per_m, H1, M_guess);
    return {p.M, p.dM_dH, p.x1, p.moved, p.mu, p.mc, p.mu_u};
  }
  // The consistent state's joint Newton solve (as JilesAthertonLaw's): the law's own inner
  // solve converges within trial_from, so M_next = M and the trial is always converged.
  struct JointTrial : Trial {
    double inv_mu_r, M_next;
    bool converged;
  };
  static void joint_trial(const RodConditions& rc, const RodState& r, const MoveStart& st,
                          double H1, double M_iter, JointTrial& t) {
    static_cast<Trial&>(t) = trial_from(rc, r, st, H1, M_iter);
    t.inv_mu_r = 1.0 / (1.0 + t.dM_dH);
    t.M_next = t.M;
    t.converged = true;
  }
  static void commit_trial(const RodConditions& rc, RodState& r, const Trial& t) {
    if (!t.moved) {
      r.preisach.last_dmc = 0.0;
      return;
    }
    r.M_A_per_m = t.M;
    physics::preisach_commit_reached(r.preisach, t.x1, t.mu, t.mc, t.mu_u);
    r.Mirr_A_per_m = rc.MsT_mag * (1.0 - rc.preisach.c) * (2.0 * r.preisach.mu_now - 1.0);
  }

  static void commit(const RodConditions& rc, RodState& r, double H1, double M_guess,
                     double* dM_dH) {
    if (H1 == r.H_A_per_m) {
      if (dM_dH) *dM_dH = reversible_susceptibility(rc, r);
      r.preisach.last_dmc = 0.0;
      return;
    }
    double x1 = 0.0;
    physics::PreisachPoint point;
    r.M_A_per_m = physics::preisach_magnetisation(H1, rc.MsT_mag, rc.preisach, r.preisach, M_guess,
                                                  dM_dH, &x1, &point);
    physics::preisach_commit_point(r.preisach, x1, point);
    r.Mirr_A_per_m = rc.MsT_mag * (1.0 - rc.preisach.c) * (2.0 * r.preisach.mu_now - 1.0);
  }

  static double reversible_susceptibility(const RodConditions& rc, const RodState& r) {
    return physics::preisach_reversible_susceptibility(r.H_A_per_m, r.M_A_per_m, rc.MsT_mag,
                                                       rc.preisach);
  }

  static double step_dissipation(const RodConditions& rc, double, double, const RodState& r) {
    return physics::preisach_last_dissipation(rc.MsT_mag, rc.preisach, r.preisach);
  }
  static double stored_energy_density(const RodConditions& rc, const RodState& r) {
    return physics::preisach_stored_energy_density(r.H_A_per_m, r.M_A_per_m, rc.MsT_mag,
                                                   rc.preisach, r.preisach);
  }

  // RK4 reference: no ODE variable; M is the law's algebraic response to H along the step
  // from the history at the step's start, committed at the end.
  static double ode_variable(const RodState&) { return 0.0; }
  static double ode_magnetisation(const RodConditions& rc, const RodState& r, double H, double,
                                  double M_guess) {
    return trial(rc, r, H, M_guess, nullptr);
  }
  static double ode_rate(const RodConditions&, double, double, double, double) { return 0.0; }
  static void ode_commit(const RodConditions& rc, RodState& r, double, double M_guess) {
    double x1 = 0.0;
    physics::PreisachPoint point;
    r.M_A_per_m = physics::preisach_magnetisation(r.H_A_per_m, rc.MsT_mag, rc.preisach, r.preisach,
                                                  M_guess, nullptr, &x1, &point);
    physics::preisach_commit_point(r.preisach, x1, point);
  }

  // The field excursion about a reversal that switches no hysteron [A/m]: a move of dx from a
  // reversal switches those with 2 h_c <= dx, none below the smallest coercive field of the
  // histogram, so 2 edge_0 H_c^T (effective field; the FRF's small-signal limit is 10 % of it).
  // The field the law's loop is shaped by, which a field-driven record must reach (identify's
  // check of a record's units): the hysterons' median coercive field H_c^T.
  static constexpr const char* characteristic_field_name = "median coercive field H_c";
  static double characteristic_field_A_per_m(const RodConditions& rc) {
    return rc.preisach.Hc_A_per_m;
  }
  // The parameter that sets the loop's width, which track's plant mismatches scale (k+/-).
  static constexpr const char* loop_width_key = "preisach.Hc0_A_per_m";

  static double reversible_field_range(const RodConditions& rc) {
    return 2.0 * rc.preisach.dist.edge[0] * rc.preisach.Hc_A_per_m;
  }

  // The FRF's anhysteretic bias (settle_at_bias; docs/model.md, "The Preisach law"): the state
  // an AC demagnetisation about the bias leaves. reduce_to_anhysteretic shrinks every coercive
  // field 1000-fold (the interaction fields stay): the hysterons then switch where their
  // interaction field is passed and the law follows its anhysteretic curve 2 F_u(x) - 1 to
  // within 1e-3 H_c, so make_state's ramp solves the circuit on that curve.
  static void reduce_to_anhysteretic(RodConditions& rc) {
    auto& d = rc.preisach.dist;
    for (double& e : d.edge) e *= kAnhystereticShrink;
    for (double& w : d.density) w /= kAnhystereticShrink;
  }
  static double anhysteretic_magnetisation(const RodConditions& rc, const RodState& r) {
    return physics::preisach_anhysteretic_magnetisation(r.H_A_per_m, rc.MsT_mag, rc.preisach,
                                                        r.M_A_per_m);
  }
  // Puts the rod in the AC-demagnetised state at its field (physics::preisach_hold_anhysteretic,
  // from M); returns how far M moved [A/m].
  static double hold_anhysteretic(const RodConditions& rc, RodState& r, double M) {
    const double held =
        physics::preisach_hold_anhysteretic(r.H_A_per_m, rc.MsT_mag, rc.preisach, r.preisach, M);
    const double moved = std::fabs(held - r.M_A_per_m);
    r.M_A_per_m = held;
    r.Mirr_A_per_m = rc.MsT_mag * (1.0 - rc.preisach.c) * (2.0 * r.preisach.mu_now - 1.0);
    return moved;
  }
  static constexpr double kAnhystereticShrink = 1e-3;
};

}  // namespace gmasim
