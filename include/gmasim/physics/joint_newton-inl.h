// The consistent magnetic state of one step, written once over the number type T (issue 38,
// item 1; docs/model.md, "The magnetic state"): the joint Newton solve of the rods' fields and
// magnetisations with the circuit, and its commit. Two instances of this one text:
//   T = double             the scalar step (src/model/step.cpp, through
//                          gmasim/physics/stages.hpp, in gmasim::physics);
//   T = lanes::Lanes<D>    the SIMD lanes (src/lanes/step_kernel-inl.h, per target), each lane
//                          one simulation, so that a lane is the scalar step by construction.
// What differs between the two is data, not arithmetic: where the rods' state lives, how the
// circuit is assembled and solved (the netlist's, or its low-rank form per lane), how a law keeps
// its trial and commits its own state, and what a failure does (a DivergenceError, or a lane's
// failure record). A context object `Ctx` gives these (the "Ctx" comment below); every number the
// solve computes is computed here.
//
// No include guard: included once per instance (laws.hpp's rule); the names it calls on T
// (select, any, all, abs, true_mask) are the number type's primitives (gmasim/physics/number.hpp).
//
// Ctx (c), for rods i = 0 .. c.rods() - 1:
//   RodMagneticT<T> load(i)              the rod's state at the step's start
//   void store(i, const RodMagneticT<T>&) the committed state
//   T kappa(i), length(i), length_per_area(i), series_reluctance(i), area(i), inv_area(i)
//   void begin(i)                          the law's move from the step's start (begin_move)
//   void trial_at(i, H, M_iter, done)      the law at (H, M_iter) where done does not hold; each
//                                          lane keeps its trial (a stopped lane its own), read by
//   T M_of(i), dM_dH(i), inv_mu_r(i), M_next(i); Mask converged(i)
//                                          the kept trial's magnetisation, slope, 1/mu_r, Newton-
//                                          corrected magnetisation, and whether the law holds
//   void branch(i, R, extra)               rod i's branch U = R phi - extra, linearised
//   Mask solve(done)                       the circuit with those branches (the coil's and the
//                                          magnets' MMF are the circuit's own); the lanes where
//                                          it failed
//   T flux(i)                              rod i's flux from the last solve
//   void newton_failed(bad, worst, worst_rod)
//                                          lanes whose solve stopped unconverged (the scalar
//                                          step throws)
//   Mask initially_done()                  lanes that failed before the step
//   void commit_law(i)                     the law's own state from its kept trial (M_irr, the
//                                          JA anchors, the Preisach stack)

// A rod's magnetic state (RodState's fields; the lanes' kH, kHc, ...): read at the step's start,
// written by the commit. H [A/m]; H_c, the field the circuit applies (eq. 7) [A/m]; the two
// previous steps' H and M (the first guess); M [A/m]; mu_r = 1 + dM/dH; tau = mu0 mu_r kappa [s];
// the rod's flux phi [Wb].
template <class T>
struct RodMagneticT {
  T H, Hc, H_prev, H_prev2, M, M_prev, M_prev2, mu_r, tau, phi;
};

// Per rod: the iterate (H, M), the flux density at the step's start B0, and the eddy terms e0 =
// H_c - H and g = 2 kappa / h (0 at rest).
template <class T, int N>
struct JointNewtonT {
  T H[N], Mg[N], B0[N], e0[N], g[N];
};

// Eq. (7), consistent reading, trapezoidal over a step h (docs/model.md): the field the circuit
// applies at the step's end, H_c1 = H1 + g (B1 - B0) - (H_c0 - H0), g = 2 kappa / h [A/(m T)].
template <class T>
GMASIM_LAW_INLINE T eddy_static_field_trapezoid(T H0, T H1, T Hc0, T B0_T, T B1_T, T g_A_per_m_T) {
  return H1 + g_A_per_m_T * (B1_T - B0_T) - (Hc0 - H0);
}

// After an undamped correction the iterate solves the circuit linearised at the last iterate
// exactly: the rods' branches and the network are linear in (H, M, phi), and M* is on the law's
// tangent. The next correction is then the circuit's response to the laws' own steps M_next - M*
// alone (law_steps: the sum of their sizes): at fixed flux a rod's field moves by -(M_next - M*)
// / mu_r, and the passive network's response adds at most as much, so |dH| <= 2 law_steps. Where
// that bound is within a quarter of every rod's field tolerance (1e-7 A/m + 1e-11 |H|), the
// iterate has converged without the confirming solve.
template <class T>
GMASIM_LAW_INLINE ::gmasim::physics::Mask<T> next_correction_within_tolerance(int n, T law_steps,
                                                                              const T* H) {
  const T bound = 2.0 * law_steps;
  ::gmasim::physics::Mask<T> within = true_mask(bound);
  for (int i = 0; i < n; ++i) within = within && (bound <= 0.25 * (1e-7 + 1e-11 * abs(H[i])));
  return within;
}

// The solve's start: each rod's move (the law's begin_move), its flux density B0 = mu0 (H + M),
// the eddy terms and the first guess, extrapolated quadratically from the last three steps (H =
// 3 (H_n - H_n-1) + H_n-2, M likewise) so that one correction usually converges. quasi_static
// (make_state's ramp): no eddy term, the guess (H_n, M_n).
template <class T, class Ctx, int N>
GMASIM_LAW_INLINE void joint_newton_start(Ctx& c, JointNewtonT<T, N>& f, bool quasi_static,
                                          T two_over_h) {
  for (int i = 0; i < c.rods(); ++i) {
    const RodMagneticT<T> r = c.load(i);
    c.begin(i);
    f.B0[i] = ::gmasim::physics::kMu0 * (r.H + r.M);
    if (quasi_static) {
      f.e0[i] = f.g[i] = 0.0;
      f.H[i] = r.H;
      f.Mg[i] = r.M;
      continue;
    }
    f.e0[i] = r.Hc - r.H;
    f.g[i] = c.kappa(i) * two_over_h;
    f.H[i] = 3.0 * (r.H - r.H_prev) + r.H_prev2;
    f.Mg[i] = 3.0 * (r.M - r.M_prev) + r.M_prev2;
  }
}

// Newton's method on the rods' fields and magnetisations jointly. At the end of the step every
// rod i satisfies, with its own law (eq. 9, or the Preisach law) and the circuit (eq. 23):
//   phi_i = A_i B_i,  B_i = mu0 (H_i + M_i(H_i)),  U_i = l_i H_c,i + R_s,i phi_i  (eq. 7, first
//   line, with k_f's series reluctance R_s), H_c,i = H_i + kappa_i dB_i/dt (trapezoidal).
// At the iterate (H*, M*) each rod's law is evaluated once (no inner solve), its magnetisation
// corrected by the law's own Newton step to M_next and linearised (slope dM/dH) into a branch
// U = R_eff phi - extra; the circuit is solved; H* moves to the field that flux implies and M*
// to M_next + dM/dH dH (the law's tangent). Quadratic; damped by 1/2 after 8 iterations (the JA
// slope jumps where M_irr starts or stops moving). A lane is done when every field correction
// is below 1e-7 A/m + 1e-11 |H| and every law holds at its iterate, or, after an undamped
// correction (iterates 1-8), when its laws hold and its next correction is bounded within a
// quarter of the tolerance (next_correction_within_tolerance: the confirming solve is skipped).
// The last evaluation, which the solve used, is what the commit commits. At the cap (60) or at a
// step that is not finite, a lane whose largest step (field or law) is within 1 mA/m is accepted
// and the others fail (c.newton_failed, named by the rod of that step).
// (GCC cannot see that the per-rod arrays are written for rods 0 .. n - 1 before they are read
// there: -Wmaybe-uninitialized is off for this function.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
template <class T, class Ctx, int N>
GMASIM_LAW_INLINE void joint_newton(Ctx& c, JointNewtonT<T, N>& f) {
  using Mk = ::gmasim::physics::Mask<T>;
  const int n = c.rods();
  Mk done = c.initially_done();
  for (int it = 0; !all(done); ++it) {
    T law_steps = 0.0;  // sum over the rods of |M_next - M*|, the laws' own Newton steps
    Mk laws_hold = true_mask(law_steps);
    for (int i = 0; i < n; ++i) {
      c.trial_at(i, f.H[i], f.Mg[i], done);
      laws_hold = laws_hold && c.converged(i);
      law_steps = law_steps + abs(c.M_next(i) - f.Mg[i]);
    }
    if (it >= 1 && it <= 8) {  // converged without the confirming solve (nor its linearisation)
      done = done || (laws_hold && next_correction_within_tolerance(n, law_steps, f.H));
      if (all(done)) break;
    }
    T Bs[N], inv_mud[N], dH[N];
    for (int i = 0; i < n; ++i) {  // each rod's branch, linearised at the iterate
      Bs[i] = ::gmasim::physics::kMu0 * (f.H[i] + c.M_next(i));
      inv_mud[i] = c.inv_mu_r(i) * (1.0 / ::gmasim::physics::kMu0);
      c.branch(i, c.length_per_area(i) * (inv_mud[i] + f.g[i]) + c.series_reluctance(i),
               -c.length(i) * (f.H[i] - Bs[i] * inv_mud[i] - f.g[i] * f.B0[i] - f.e0[i]));
    }
    done = done || c.solve(done);
    T worst = 0.0, worst_rod = 0.0;
    Mk converged = true_mask(worst);
    for (int i = 0; i < n; ++i) {
      dH[i] = (c.flux(i) * c.inv_area(i) - Bs[i]) * inv_mud[i];
      // The rod's Newton step: its field's and its law's (A/m both); NaN propagates.
      const T adH = abs(dH[i]);
      const T dM = abs(c.M_next(i) - f.Mg[i]);
      const T step = select(dM <= adH, adH, dM);
      const Mk larger = !(step <= worst);
      worst = select(larger, step, worst);
      worst_rod = select(larger, T(static_cast<double>(i)), worst_rod);
      converged = converged && c.converged(i) && adH <= 1e-7 + 1e-11 * abs(f.H[i]);
    }
    done = done || converged;
    // Not finite (a step >= 0 or NaN beyond the largest double), or at the cap: stop.
    const Mk cap = it == 60 ? true_mask(worst) : !true_mask(worst);
    const Mk stop = !done && (!(worst <= 1.7976931348623157e308) || cap);
    const Mk bad = stop && !(worst <= 1e-3);  // 1 mA/m: far below what the outputs resolve
    if (any(bad)) c.newton_failed(bad, worst, worst_rod);
    done = done || stop;
    if (all(done)) break;
    const double damping = it < 8 ? 1.0 : 0.5;
    for (int i = 0; i < n; ++i) {  // the lanes still iterating: the next iterate
      const T step = damping * dH[i];
      f.H[i] = select(done, f.H[i], f.H[i] + step);
      f.Mg[i] = select(done, f.Mg[i], c.M_next(i) + c.dM_dH(i) * step);
    }
  }
}
#pragma GCC diagnostic pop

// The commit of the step's end: the last trial at H1 as it is (its M, the law's own state, and
// the flux density B1 = mu0 (H1 + M)), the eddy field (eq. 7, trapezoidal; at rest H_c = H1),
// the first guess's histories, mu_r = 1 + dM/dH, tau = mu0 mu_r kappa and the rod's flux.
template <class T, class Ctx, int N>
GMASIM_LAW_INLINE void joint_newton_commit(Ctx& c, const JointNewtonT<T, N>& f, bool quasi_static) {
  for (int i = 0; i < c.rods(); ++i) {
    const T H1 = f.H[i], M1 = c.M_of(i);
    const T B1 = ::gmasim::physics::kMu0 * (H1 + M1);
    RodMagneticT<T> r = c.load(i);
    const T H0 = r.H;
    r.M_prev2 = r.M_prev;
    r.M_prev = r.M;
    r.M = M1;
    c.commit_law(i);
    r.Hc = quasi_static ? H1 : eddy_static_field_trapezoid<T>(H0, H1, r.Hc, f.B0[i], B1, f.g[i]);
    r.H_prev2 = r.H_prev;
    r.H_prev = H0;
    r.H = H1;
    r.mu_r = 1.0 + c.dM_dH(i);
    r.tau = ::gmasim::physics::kMu0 * r.mu_r * c.kappa(i);
    r.phi = B1 * c.area(i);
    c.store(i, r);
  }
}
