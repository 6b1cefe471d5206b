// The Jiles-Atherton law (eq. 9) over the number type T (gmasim/physics/number.hpp), written
// once; the second part of the step's laws (gmasim/physics/laws-inl.h: its conventions). No
// include guard and no #include: included inside a namespace after laws-inl.h, once per instance
// (gmasim/physics/laws.hpp for double; src/lanes/number_lanes-inl.h per SIMD target).
// Eq. (9): the Jiles-Atherton law (gmasim/physics/jiles_atherton.hpp has its scalar
// conveniences, the temperature laws of eq. 10 and the energy). `where` (a mask): the lanes that
// evaluate -- a lane outside it has its anchors and results left alone, as the scalar step,
// which does not evaluate there, leaves them.

// Langevin function L(x) = coth x - 1/x and its derivative L'(x) = 1/x^2 - 1/sinh^2 x,
// from one exponential and one division (1/(x (1 - e)) gives 1/x and 1/(1 - e)); Taylor
// series for |x| < 0.1 (truncation below 1e-16 relative).
template <class T>
struct LangevinValueT {
  T L, dL;
};
// The closed form for 0.1 <= |x| <= 40 from e = exp(-2|x|) (coth|x| = (1+e)/(1-e)).
template <class T>
GMASIM_LAW_INLINE LangevinValueT<T> langevin_pair_from_exp(T x, T e) {
  const T one_minus_e = 1.0 - e;
  const T q = 1.0 / (x * one_minus_e);
  const T inv_x = one_minus_e * q;
  const T inv_1me = x * q;  // 1 / (1 - e)
  const T coth_abs = (1.0 + e) * inv_1me;
  const T inv_sinh2 = 4.0 * e * inv_1me * inv_1me;
  return {select(x > 0.0, coth_abs, -coth_abs) - inv_x, inv_x * inv_x - inv_sinh2};
}
template <class T>
GMASIM_LAW_INLINE LangevinValueT<T> langevin_series(T x) {
  const T x2 = x * x;
  return {x * (1.0 / 3.0 -
               x2 * (1.0 / 45.0 - x2 * (2.0 / 945.0 - x2 * (1.0 / 4725.0 - x2 * (2.0 / 93555.0))))),
          1.0 / 3.0 -
              x2 * (1.0 / 15.0 - x2 * (2.0 / 189.0 - x2 * (1.0 / 675.0 - x2 * (2.0 / 10395.0))))};
}
template <class T>
GMASIM_LAW_INLINE LangevinValueT<T> langevin_asymptote(T x) {
  const T inv_x = 1.0 / x;
  return {select(x > 0.0, T(1.0), T(-1.0)) - inv_x, inv_x * inv_x};
}
// The three regimes, given e = exp(-2|x|) where the closed form applies (langevin_closed).
template <class T>
GMASIM_LAW_INLINE ::gmasim::physics::Mask<T> langevin_closed(T x) {
  const T ax = abs(x);
  return !(ax < 0.1) && !(ax > 40.0);
}
template <class T>
GMASIM_LAW_INLINE LangevinValueT<T> langevin_regimes(T x, T e) {
  const T ax = abs(x);
  const ::gmasim::physics::Mask<T> small = ax<0.1, big = ax> 40.0;
  if (all(small)) return langevin_series(x);
  if (all(big)) return langevin_asymptote(x);
  LangevinValueT<T> v = langevin_pair_from_exp(x, e);
  if (any(small)) {
    const LangevinValueT<T> t = langevin_series(x);
    v = {select(small, t.L, v.L), select(small, t.dL, v.dL)};
  }
  if (any(big)) {
    const LangevinValueT<T> t = langevin_asymptote(x);
    v = {select(big, t.L, v.L), select(big, t.dL, v.dL)};
  }
  return v;
}
template <class T>
GMASIM_LAW_INLINE LangevinValueT<T> langevin_pair(T x) {
  const ::gmasim::physics::Mask<T> closed = langevin_closed(x);
  T e = 0.0;
  if (any(closed)) e = each(::gmasim::physics::LibmExp{}, -2.0 * abs(x), closed);
  return langevin_regimes(x, e);
}
// langevin_pair with its exponential exp(-2|x|) from an anchor nearby (p, exp_near: a few units
// in the last place from langevin_pair; p moves where it is not near), and from the solve's last
// value `recent` beside it where given (exp_near(y, p, recent)), in the lanes of where.
template <class T>
GMASIM_LAW_INLINE LangevinValueT<T> langevin_pair_near(T x, ExpPointT<T>& p, ExpPointT<T>* recent,
                                                       ::gmasim::physics::Mask<T> where) {
  const ::gmasim::physics::Mask<T> closed = langevin_closed(x);
  T e = 0.0;
  if (any(closed)) {
    const T y = -2.0 * abs(x);
    e = recent ? exp_near(y, p, *recent, where && closed) : exp_near(y, p, where && closed);
  }
  return langevin_regimes(x, e);
}

// exp(-r), q(r) = (1 - exp(-r))/r and dq/dr = (E - q)/r (ja_irreversible_update), from one
// reciprocal of r; q by its Taylor series for r < 1e-2 (truncation below 1e-16 relative),
// where 1 - exp(-r) would cancel; dq/dr = -1/2 at r <= 1e-12.
template <class T>
struct LagWeightsSlopeT {
  T E, q, dq_dr;
};
template <class T>
GMASIM_LAW_INLINE LagWeightsSlopeT<T> lag_weights_and_slope_from(T r, T E) {
  const ::gmasim::physics::Mask<T> small = r < 1e-2;
  LagWeightsSlopeT<T> w{E, 0.0, 0.0};
  if (!all(small)) {
    const T inv_r = 1.0 / r;
    w.q = (1.0 - E) * inv_r;
    w.dq_dr = (E - w.q) * inv_r;
  }
  if (any(small)) {
    const T q =
        1.0 - r * (1.0 / 2 - r * (1.0 / 6 - r * (1.0 / 24 - r * (1.0 / 120 - r * (1.0 / 720)))));
    w.q = select(small, q, w.q);
    w.dq_dr = select(small, select(r > 1e-12, (E - q) / r, T(-0.5)), w.dq_dr);
  }
  return w;
}
// With exp(-r) from an anchor nearby (p, exp_near; moved where it is not), and from the solve's
// last value `recent` beside it where given (exp_near(y, p, recent)), in the lanes of where.
template <class T>
GMASIM_LAW_INLINE LagWeightsSlopeT<T> lag_weights_and_slope_near(T r, ExpPointT<T>& p,
                                                                 ExpPointT<T>* recent,
                                                                 ::gmasim::physics::Mask<T> where) {
  return lag_weights_and_slope_from(
      r, recent ? exp_near(-r, p, *recent, where) : exp_near(-r, p, where));
}

// The four JA coefficients at one temperature (eq. 10 evaluated).
template <class T>
struct JaCoefficientsT {
  T a_A_per_m;  // shape coefficient a^T of the anhysteretic curve
  T alpha;      // domain-interaction coefficient alpha^T (dimensionless)
  T c;          // reversible coefficient c^T (dimensionless)
  T k_A_per_m;  // pinning coefficient k^T
};

// Eq. (9), second line, integrated over one step. dM_irr/dH_e = (M_an - M_irr)/(k delta)
// with delta = sign(dH_e) is, along the path length s = |H_e - H_e0|, the first-order
// relaxation  k dM_irr/ds = M_an - M_irr : a lag of M_irr behind M_an with "time
// constant" k. With M_an linear in s over the step (first-order hold) it has the same
// exact update as the eddy lag (magnetic.hpp), which is unconditionally stable however
// small k or large the field step. The guard of Jiles (1992), no change while
// (M_an - M_irr) delta <= 0, holds M_irr until M_an crosses it.
// Returns M_irr at the end of the step and, in dMirr_dHe1, its derivative with respect to
// the end field H_e1 given dMan1 = dM_an/dH_e there (for Newton's method in ja_step).
// inv_k = 1/k (JaMoveStart: one division per move, not two per evaluation). exp(-r) from the
// anchor `lag` where it is near, or from the solve's last value lag_recent (exp_near; lag moves
// where neither is near), in the lanes of where.
template <class T>
GMASIM_LAW_INLINE T ja_irreversible_update(T Mirr0, T Man0, T Man1, T dMan1, T dHe, T inv_k,
                                           T& dMirr_dHe1, ExpPointT<T>& lag,
                                           ExpPointT<T>* lag_recent,
                                           ::gmasim::physics::Mask<T> where) {
  const T delta = select(dHe > 0.0, T(1.0), T(-1.0));
  const T d0 = (Man0 - Mirr0) * delta, d1 = (Man1 - Mirr0) * delta;
  // dHe == 0: nothing moves; d0, d1 <= 0: pinned for the whole step
  const ::gmasim::physics::Mask<T> still = dHe == 0.0 || (d0 <= 0.0 && d1 <= 0.0);
  if (all(still)) {
    dMirr_dHe1 = 0.0;
    return Mirr0;
  }
  T s = abs(dHe), u0 = Man0;
  T ds_dHe1 = delta;  // d|He1 - He0| / dHe1
  const ::gmasim::physics::Mask<T> cross = d0 <= 0.0 && !still;
  if (any(cross)) {  // M_an crosses M_irr inside the step: relax over the remainder only
    const T frac = d1 / (d1 - d0);
    // d frac / dHe1 = -d0 (dd1/dHe1) / (d1 - d0)^2 with dd1/dHe1 = delta dMan1.
    ds_dHe1 =
        select(cross, delta * frac - s * d0 * delta * dMan1 / ((d1 - d0) * (d1 - d0)), ds_dHe1);
    s = select(cross, s * frac, s);
    u0 = select(cross, Mirr0, u0);
  }
  const T r = s * inv_k;
  // d/dHe1 through M_an1 (weight 1 - q) and through r = s/k (dq/dr = (E - q)/r): one
  // reciprocal of r for q and dq/dr (lag_weights_and_slope_from).
  const ::gmasim::physics::Mask<T> moves = where && !still;
  const LagWeightsSlopeT<T> w = lag_weights_and_slope_near(r, lag, lag_recent, moves);
  const T dq_dr = w.dq_dr;
  const T dm = (1.0 - w.q) * dMan1 + ds_dHe1 * inv_k * (-(Mirr0 - u0) * w.E - (Man1 - u0) * dq_dr);
  const T m1 = Man1 + (Mirr0 - u0) * w.E - (Man1 - u0) * w.q;
  dMirr_dHe1 = select(still, T(0.0), dm);
  return select(still, Mirr0, m1);
}

// What a move depends on at its start only: H_e0 = H0 + alpha M0 and M_an(H_e0), fixed while a
// caller tries several end fields H1 from the same start; 1/a and 1/k for its evaluations.
template <class T>
struct JaMoveStartT {
  T He0, Man0;
  T inv_a;  // 1 / a^T, for the move's evaluations (ja_evaluate)
  T inv_k;  // 1 / k^T, likewise (ja_irreversible_update)
};
// With the Langevin function known at a nearby x_at = H_e / a (L and L' there, lv; the last
// evaluation of the law, where the last step ended): where |H_e0 / a - x_at| <= 1e-7, M_an(H_e0)
// = M_s^T (L(x_at) + L'(x_at) (x0 - x_at)), whose truncation (|L''| <= 0.5: below 3e-15 M_s^T)
// is far below eq. (9)'s tolerance; otherwise M_s^T L(x0) (langevin_pair). x_at NaN: nothing
// known. (The consistent state commits its last iterate, so a step starts within about alpha
// 1e-12 M_s^T / a of it: one exponential less per rod and step.) inv_a = 1/a and inv_k = 1/k,
// divided once with the coefficients (RodConditions).
template <class T>
GMASIM_LAW_INLINE JaMoveStartT<T> ja_move_start_near(T H0, T M0, T MsT_A_per_m,
                                                     const JaCoefficientsT<T>& p, T inv_a, T inv_k,
                                                     T x_at, const LangevinValueT<T>& lv) {
  const T He0 = H0 + p.alpha * M0;
  const T x0 = He0 * inv_a;
  const ::gmasim::physics::Mask<T> near = abs(x0 - x_at) <= 1e-7;
  T Man0 = MsT_A_per_m * (lv.L + lv.dL * (x0 - x_at));
  if (!all(near)) Man0 = select(near, Man0, MsT_A_per_m * langevin_pair(x0).L);
  return {He0, Man0, inv_a, inv_k};
}

// The anchors of an evaluation's exponentials (exp(-2|x|) of the Langevin function, exp(-r) of
// the lag; exp_near), for the next evaluations nearby: a Newton solve's next iterate and the
// next step's (RodState::ja_exp). No anchor: y NaN (no_ja_exp_points).
template <class T>
struct JaExpPointsT {
  ExpPointT<T> langevin, lag;
};
template <class T>
GMASIM_LAW_INLINE JaExpPointsT<T> no_ja_exp_points() {
  const T nan = __builtin_nan("");
  return {{nan, 0.0}, {nan, 0.0}};
}

// One evaluation of eq. (9) at the end field H1 and a magnetisation iterate M1 (inv_a = 1/a):
// M_irr1 from ja_irreversible_update, the magnetisation the law gives there,
//   F(M1) = (1-c) M_irr1 + c M_an(H1 + alpha M1),
// and chi_e = dF/dH_e. Eq. (9) holds where g = M1 - F(M1) = 0; its Newton step in M1 is
// -g / (1 - alpha chi_e) (ja_step_from iterates it; the consistent state's joint Newton solve
// takes one per circuit solve). `near`: the anchors of the exponentials (moved where they are
// not near); `recent` (or null): the exponentials' last values in the same solve, which the next
// iterate, much nearer, starts from (exp_near(y, a, recent)); both only in the lanes of where.
template <class T>
struct JaEvaluationT {
  T Mirr1, M, chi_e;
  T x1;                  // H_e1 / a, where the Langevin function was evaluated
  LangevinValueT<T> lv;  // L and L' at x1
};
template <class T>
[[gnu::always_inline]] GMASIM_LAW_INLINE JaEvaluationT<T> ja_evaluate(
    const JaMoveStartT<T>& st, T H1, T M1, T MsT_A_per_m, const JaCoefficientsT<T>& p, T Mirr0,
    T inv_a, JaExpPointsT<T>& near, JaExpPointsT<T>* recent, ::gmasim::physics::Mask<T> where) {
  const T He1 = H1 + p.alpha * M1;
  const LangevinValueT<T> lv =
      langevin_pair_near(He1 * inv_a, near.langevin, recent ? &recent->langevin : nullptr, where);
  const T Man1 = MsT_A_per_m * lv.L;
  const T dMan = MsT_A_per_m * inv_a * lv.dL;
  T dMirr = 0.0;
  const T Mirr1 = ja_irreversible_update(Mirr0, st.Man0, Man1, dMan, He1 - st.He0, st.inv_k, dMirr,
                                         near.lag, recent ? &recent->lag : nullptr, where);
  return {Mirr1, (1.0 - p.c) * Mirr1 + p.c * Man1, (1.0 - p.c) * dMirr + p.c * dMan, He1 * inv_a,
          lv};
}

// The tolerance on g = M1 - F(M1) at which eq. (9) counts as solved [A/m]: 1e-12 M_s^T.
template <class T>
GMASIM_LAW_INLINE T ja_magnetisation_tolerance(T MsT_A_per_m) {
  return 1e-12 * MsT_A_per_m;
}
// The consistent state's safeguard [A/m]: where a joint Newton iterate's residual |g| exceeds
// 1e-3 M_s^T, eq. (9) is solved at the trial field first (ja_joint_trial). A jump of the current
// from rest to 6 A in one step still leaves |g| above it (tests/test_lanes.cpp,
// SafeguardSolvesEq9WhereTheScalarLawDoes); the quadratic first guess at 200 steps a period
// mostly does not. It was 1e-5 M_s^T: the joint solve converges from these guesses in a few more
// iterates, cheaper than the inner solve (measured in one gmasim_bench run: the 12-condition
// objective on the scalar step 3.95 -> 3.10 ms an evaluation, its lanes 1.94 -> 1.62 ms; 1e-2
// and 1e-4 no better), and every result stays within the solve's tolerance (calibration_smoke's
// start RMS moved 4e-12 relative; docs/calibration.md).
template <class T>
GMASIM_LAW_INLINE T ja_safeguard_residual(T MsT_A_per_m) {
  return 1e-3 * MsT_A_per_m;
}

// One step of eq. (9) from applied field H0 to H1, in the lanes of where. Solves for the end
// magnetisation M1 the scalar equation  g(M1) = M1 - (1-c) M_irr1(M1) - c M_an(H1 + alpha M1) =
// 0  by Newton's method with its exact derivative (H_e depends on M through alpha), M_irr1 from
// ja_irreversible_update, from M_guess (e.g. a linear extrapolation): steps -g / max(1 - alpha
// chi_e, 0.2), each lane stopping where |g| <= 1e-12 M_s^T or at the 60th evaluation. The step's
// start enters through st (ja_move_start_near). Returns M1 and M_irr1 in M1_out and Mirr1_out;
// chi_e_out receives chi_e = (1-c) dM_irr1/dH_e + c dM_an/dH_e at H1, from which dM1/dH1 = chi_e
// / (1 - alpha chi_e) (the implicit-function derivative of g). At H1 == H0 nothing moves: M_irr1
// = M_irr0, M1 = M0 and chi_e is the reversible c dM_an/dH_e. Outside where the outputs are kept.
template <class T>
GMASIM_LAW_RARE void ja_step_from(T H0, const JaMoveStartT<T>& st, T H1, T MsT_A_per_m,
                                  const JaCoefficientsT<T>& p, T Mirr0, T M0, T M_guess,
                                  T& Mirr1_out, T& M1_out, T& chi_e_out,
                                  ::gmasim::physics::Mask<T> where) {
  const T inv_a = 1.0 / p.a_A_per_m;
  const ::gmasim::physics::Mask<T> same = where && H1 == H0;
  if (any(same)) {
    const LangevinValueT<T> lv = langevin_pair((H0 + p.alpha * M0) * inv_a);
    Mirr1_out = select(same, Mirr0, Mirr1_out);
    M1_out = select(same, M0, M1_out);
    chi_e_out = select(same, p.c * MsT_A_per_m * inv_a * lv.dL, chi_e_out);
  }
  const T tol = ja_magnetisation_tolerance(MsT_A_per_m);
  T M1 = M_guess;
  ::gmasim::physics::Mask<T> left = where && !same;
  for (int it = 0; it < 60 && any(left); ++it) {
    JaExpPointsT<T> none_yet = no_ja_exp_points<T>();
    const JaEvaluationT<T> e = ja_evaluate(st, H1, M1, MsT_A_per_m, p, Mirr0, inv_a, none_yet,
                                           static_cast<JaExpPointsT<T>*>(nullptr), left);
    const T g = M1 - e.M;
    const ::gmasim::physics::Mask<T> every = true_mask(g);
    const ::gmasim::physics::Mask<T> stop = left && (it == 59 ? every : abs(g) <= tol);
    Mirr1_out = select(stop, e.Mirr1, Mirr1_out);
    M1_out = select(stop, e.M, M1_out);
    chi_e_out = select(stop, e.chi_e, chi_e_out);
    left = left && !stop;
    T dg = 1.0 - p.alpha * e.chi_e;
    dg = select(dg < 0.2, T(0.2), dg);  // alpha > 0 (positive feedback): damp the Newton step
    M1 = select(left, M1 - g / dg, M1);
  }
}

// The slope dM/dH = chi_e / (1 - alpha chi_e) along a step with what the consistent state's
// Newton solve needs beside it, from one division: with d = 1 - alpha chi_e,
//   dM/dH = chi_e / d,   1/mu_r = 1/(1 + dM/dH) = d / (d + chi_e),   1/d,
// the last for the Newton step -g/d of eq. (9) in M (ja_evaluate), d held >= 0.2 as in
// ja_step_from (alpha > 0 is positive feedback).
template <class T>
struct JaSlopeTermsT {
  T dM_dH, inv_mu_r, inv_dg;
};
template <class T>
GMASIM_LAW_INLINE JaSlopeTermsT<T> ja_slope_terms(T chi_e, const JaCoefficientsT<T>& p) {
  const T d = 1.0 - p.alpha * chi_e, dc = d + chi_e;
  const T inv = 1.0 / (d * dc);
  return {chi_e * dc * inv, d * d * inv, select(d >= 0.2, dc * inv, T(5.0))};
}

// The consistent state's joint Newton solve in (H, M), the law's part (JilesAthertonLaw::
// joint_trial; the lanes' JilesAthertonLanes): one evaluation of eq. (9) at the end field H1 and
// the iterate M_iter (ja_evaluate), no inner solve, from the move's start st (its anchors `near`
// and the solve's `recent`, both moved as the evaluation moves them), in the lanes of `live`
// (the others' anchors are left alone). The rod's state at the move's start: H0, M_irr0, M0 and
// the law's last evaluation (x_at, L, L'). Gives the law's state there (M = F(M_iter), M_irr),
// the slope dM/dH, 1/mu_r = 1/(1 + dM/dH), the Newton-corrected magnetisation M_next = M_iter -
// g/(1 - alpha chi_e) the circuit is linearised about, whether eq. (9) holds at M_iter to its
// tolerance (|g| <= 1e-12 M_s^T), the evaluation carried to the next step (the rod's own where
// nothing moves) and where eq. (9) was solved fully (the safeguard). At H1 == H0 nothing moves
// (ja_step_from): M = M_next = M0. Where |g| > 1e-3 M_s^T (ja_safeguard_residual: a poor guess,
// large or violent steps) eq. (9) is solved at H1 by ja_step_from from the Newton-corrected
// guess: M_next = M.
template <class T>
struct JaJointTrialT {
  T M, dM_dH, Mirr, inv_mu_r, M_next;
  T an_x;                   // where the law was evaluated (H_e / a)
  LangevinValueT<T> an_lv;  // L and L' there
  ::gmasim::physics::Mask<T> converged, solved;
};
template <class T>
GMASIM_LAW_INLINE JaJointTrialT<T> ja_joint_trial(T H0, T Mirr0, T M0, T an_x,
                                                  const LangevinValueT<T>& an_lv, T MsT_A_per_m,
                                                  const JaCoefficientsT<T>& p,
                                                  const JaMoveStartT<T>& st, JaExpPointsT<T>& near,
                                                  JaExpPointsT<T>& recent, T H1, T M_iter,
                                                  ::gmasim::physics::Mask<T> live) {
  JaJointTrialT<T> t;
  const ::gmasim::physics::Mask<T> same = H1 == H0, moves = live && !same;
  T chi_e = 0.0, g = 0.0;
  t.Mirr = Mirr0;
  t.M = M0;
  if (any(same))  // nothing moves (ja_step_from): M_irr0, M0 and the reversible chi_e
    ja_step_from(H0, st, H1, MsT_A_per_m, p, Mirr0, M0, M_iter, t.Mirr, t.M, chi_e, same);
  t.an_x = an_x;  // nothing evaluated: the rod's own point stays
  t.an_lv = an_lv;
  t.solved = !true_mask(H1);  // no lane yet
  if (!all(same)) {
    const JaEvaluationT<T> e =
        ja_evaluate(st, H1, M_iter, MsT_A_per_m, p, Mirr0, st.inv_a, near, &recent, moves);
    t.an_x = select(same, t.an_x, e.x1);
    t.an_lv = {select(same, t.an_lv.L, e.lv.L), select(same, t.an_lv.dL, e.lv.dL)};
    t.Mirr = select(same, t.Mirr, e.Mirr1);
    t.M = select(same, t.M, e.M);
    chi_e = select(same, chi_e, e.chi_e);
    g = select(same, g, M_iter - e.M);
    const ::gmasim::physics::Mask<T> far = !same && abs(g) > ja_safeguard_residual(MsT_A_per_m);
    t.solved = far;
    if (any(far)) {  // far from eq. (9): solve it (ja_step_from)
      T dg = 1.0 - p.alpha * chi_e;
      dg = select(dg < 0.2, T(0.2), dg);  // std::max(1 - alpha chi_e, 0.2)
      ja_step_from(H0, st, H1, MsT_A_per_m, p, Mirr0, M0, M_iter - g / dg, t.Mirr, t.M, chi_e, far);
      g = select(far, T(0.0), g);
    }
  }
  M_iter = select(same || t.solved, t.M, M_iter);
  const JaSlopeTermsT<T> sl = ja_slope_terms(chi_e, p);
  t.dM_dH = sl.dM_dH;
  t.inv_mu_r = sl.inv_mu_r;
  t.M_next = M_iter - g * sl.inv_dg;
  t.converged = abs(g) <= ja_magnetisation_tolerance(MsT_A_per_m);
  return t;
}
