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
  static void commit(const RodConditions& rc, RodState& r, double H1, double M_guess,
                     double* dM_dH) {
    if (H1 == r.H_A_per_m) {
      if (dM_dH) *dM_dH = reversible_susceptibility(rc, r);
      r.preisach.last_dmc = 0.0;
      return;
    }
    double x1 = 0.0;
    r.M_A_per_m = physics::preisach_magnetisation(H1, rc.MsT_mag, rc.preisach, r.preisach, M_guess,
                                                  dM_dH, &x1);
    physics::preisach_commit(rc.preisach.dist, r.preisach, x1);
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
    r.M_A_per_m = physics::preisach_magnetisation(r.H_A_per_m, rc.MsT_mag, rc.preisach, r.preisach,
                                                  M_guess, nullptr, &x1);
    physics::preisach_commit(rc.preisach.dist, r.preisach, x1);
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
