// The step's laws over the number type T (gmasim/physics/number.hpp), written once. No include
// guard and no #include: this text is included inside a namespace, once per instance --
//   gmasim::physics (gmasim/physics/laws.hpp), T = double: the scalar step;
//   gmasim::lanes::<target> (src/lanes/number_lanes-inl.h), T = Lanes<D>, once per SIMD target,
//   so that each target's code is compiled for that target (Highway's foreach_target).
// Before it, the namespace must declare the primitives of T (select, any, all, none, abs, sqrt,
// each; for double gmasim/physics/number.hpp) and oscillator_free_closed_form_where; the scalar
// helpers it names with ::gmasim::physics:: (gmasim/physics/laws.hpp) must be declared.
// GMASIM_LAW_INLINE marks a law's function, GMASIM_LAW_RARE one on a rare path (the instance
// defines them: `inline` for double; always and never inlined in the lanes, where a vector
// argument of an out-of-line call goes through memory).
// Each function is one law and cites its equation; the scalar and the lane instances are the
// same text, so a lane computes what the scalar step computes, bit for bit.
// c0 + c1 x + ... + c7 x^7 by Estrin's scheme (short dependency chains).
template <class T>
GMASIM_LAW_INLINE T polynomial7(T x, const double (&c)[8]) {
  const T x2 = x * x, x4 = x2 * x2;
  return (c[0] + c[1] * x) + x2 * (c[2] + c[3] * x) +
         x4 * ((c[4] + c[5] * x) + x2 * (c[6] + c[7] * x));
}

// e^x to (x^8 / 8!): below 1e-19 relative where |x| <= 1/64.
template <class T>
GMASIM_LAW_INLINE T exp_series7(T x) {
  constexpr double kExp[8] = {1.0,      1.0,       1.0 / 2,   1.0 / 6,
                              1.0 / 24, 1.0 / 120, 1.0 / 720, 1.0 / 5040};
  return polynomial7(x, kExp);
}

// e^x - 1 to (x^11 / 11!): below 3e-18 relative to e^x where |x| <= 1/8.
template <class T>
GMASIM_LAW_INLINE T expm1_series10(T x) {
  const T x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
  return x * (((1.0 + x * (1.0 / 2)) + x2 * (1.0 / 6 + x * (1.0 / 24))) +
              x4 * ((1.0 / 120 + x * (1.0 / 720)) + x2 * (1.0 / 5040 + x * (1.0 / 40320))) +
              x8 * (1.0 / 362880 + x * (1.0 / 3628800)));
}

// cos(pi m / 2) for |m| <= 1 from its Taylor series in t = m^2 to t^10 (truncation below 2e-17,
// absolute; rounding a few 1e-16 absolute, where std::cos(0.5 * pi * m) is itself 6e-17 off at
// m = 1 through the rounding of pi/2): no range reduction. std::cos elsewhere.
template <class T>
GMASIM_LAW_INLINE T cos_half_pi(T m) {
  const ::gmasim::physics::Mask<T> in = abs(m) <= 1.0;
  if (none(in)) return each(::gmasim::physics::CosHalfPiLibm{}, m, !in);
  const T t = m * m, t2 = t * t, t4 = t2 * t2, t8 = t4 * t4;
  const T series =
      ((1.0 - 1.2337005501361697 * t) + t2 * (0.25366950790104803 - 0.02086348076335296 * t)) +
      t4 * ((0.0009192602748394266 - 2.5202042373060607e-05 * t) +
            t2 * (4.710874778818172e-07 - 6.386603083791852e-09 * t)) +
      t8 * ((6.565963114979473e-11 - 5.294400200734623e-13 * t) + t2 * 3.437739179098607e-15);
  if (all(in)) return series;
  return select(in, series, each(::gmasim::physics::CosHalfPiLibm{}, m, !in));
}

// A known exponential: e = e^y; y NaN: none.
template <class T>
struct ExpPointT {
  T y, e;
};

// e^y from an anchor a = (y_a, e^{y_a}) that std::exp computed: e^{y_a} + e^{y_a} (e^d - 1),
// d = y - y_a, by expm1_series10 where |d| <= 1/8; otherwise (or where a.y is NaN: no anchor)
// std::exp(y), and a becomes (y, e^y). The anchor moves only there, so every value is one series
// and two roundings away from a std::exp value (within 2 units in the last place of std::exp(y),
// test Series.ExpNearIsWithinAFewUlp), however long the anchor is kept: over a Newton solve's
// iterates and from step to step (RodState::ja_exp, prestress_exp).
// Only where `where` holds (the lanes that evaluate this exponential: a moves exactly where the
// scalar step moves it; the value elsewhere is not used).
template <class T>
GMASIM_LAW_INLINE T exp_near(T y, ExpPointT<T>& a, ::gmasim::physics::Mask<T> where) {
  const T d = y - a.y;
  const ::gmasim::physics::Mask<T> moves = where && !(abs(d) <= 1.0 / 8);
  if (none(moves)) return a.e + a.e * expm1_series10(d);
  const T fresh = each(::gmasim::physics::LibmExp{}, y, moves);
  if (all(moves)) {
    a = {y, fresh};
    return a.e;
  }
  const T series = a.e + a.e * expm1_series10(d);  // a lane whose anchor is near
  a = {select(moves, y, a.y), select(moves, fresh, a.e)};
  return select(moves, fresh, series);
}
template <class T>
GMASIM_LAW_INLINE T exp_near(T y, ExpPointT<T>& a) {
  return exp_near(y, a, true_mask(y));
}

// e^y near the last value of the same Newton solve: from `recent` (y_r, e^{y_r}), a value
// exp_near(y_r, a) returned, as e^{y_r} (1 + d + d^2/2 + d^3/6), d = y - y_r, where |d| <= 2^-13
// (truncation below 1e-17 relative; the consistent state's iterates after the first move the
// law's exponents by 1e-5 at most); otherwise exp_near(y, a), and recent becomes (y, that value).
// recent holds only exp_near's values and lives for one solve (JilesAthertonLaw::MoveStart), so
// every value is at most two short series and four roundings from a std::exp value.
template <class T>
GMASIM_LAW_INLINE T exp_near(T y, ExpPointT<T>& a, ExpPointT<T>& recent,
                             ::gmasim::physics::Mask<T> where) {
  const T d = y - recent.y;
  const ::gmasim::physics::Mask<T> go = where && !(abs(d) <= 1.0 / 8192);
  if (none(go)) return recent.e + recent.e * (d * (1.0 + d * (1.0 / 2 + d * (1.0 / 6))));
  const T v = exp_near(y, a, go);
  if (all(go)) {
    recent = {y, v};
    return recent.e;
  }
  const T series = recent.e + recent.e * (d * (1.0 + d * (1.0 / 2 + d * (1.0 / 6))));
  recent = {select(go, y, recent.y), select(go, v, recent.e)};
  return select(go, v, series);
}

// e^y where the last call with this p may have had the same y (a step's fixed decay over a run
// at one time step): p's value when y == p.y, std::exp(y) otherwise, bit for bit either way.
// Only where `where` holds (the lanes that take this exponential; elsewhere p is kept and the
// value is not used): p then changes exactly where the scalar step changes it.
template <class T>
GMASIM_LAW_INLINE T exp_cached(T y, ExpPointT<T>& p, ::gmasim::physics::Mask<T> where) {
  const ::gmasim::physics::Mask<T> update = where && !(y == p.y);
  if (any(update))
    p = {select(update, y, p.y),
         select(update, each(::gmasim::physics::LibmExp{}, y, update), p.e)};
  return p.e;
}

// The transition matrix of the free row, m e'' + c e' + k e = 0, over a step h:
// with A h = [[0, h], [-k h / m, -c h / m]] (trace tau = -c h / m, determinant
// delta = k h^2 / m), exp(A h) = f0 I + f1 A h. N = A h - tau/2 I has N^2 = u
// I, u = tau^2/4 - delta = -(w_d h)^2, so exp(N) = C I + S N with C = sum u^j /
// (2j)! (cos w_d h) and S = sum u^j / (2j+1)! (sin(w_d h) / (w_d h); cosh and
// sinh where u > 0, over-damped), and
//   f1 = e^(tau/2) S,   f0 = e^(tau/2) (C - tau/2 S).
// C and S are summed to u^7 (truncation below 1e-18; Estrin's scheme) at u / 4^n, n the
// fewest halvings that bring it within 1/4 (none where w_d h <= 1/2: at least 12 steps per
// period), and doubled n times (oscillator_series_doubled: exp(N) = exp(N/2)^2); e^(tau/2) by
// its series to (tau/2)^7 where |tau/2| <= 1/64 (below 1e-19) and by std::exp beyond: no sincos
// or square root, every damping alike. Over-damped (u > 0) up to |u| = 4 (w_d h <= 2: cosh and
// sinh grow with u and cancel against e^(tau/2)); under-damped (u < 0) up to |u| =
// kOscillatorSeriesUnder (w_d h <= 256, eight halvings): the doublings turn (C, S w_d h) as
// rotations, their rounding growing as 2^n -- 5.6e-14 of e^(tau/2) at the cap against a long
// double reference, where the closed form is 1.7e-14 off (tests/test_physics.cpp,
// Oscillator.LongStepsTakeTheSeriesToItsCap). A step of many of the row's periods (the
// identification's 200 steps a period at 10 Hz: w_d h ~ 40 for the 8-13 kHz rods) takes the
// series; valid = false beyond the caps: the closed form.
template <class T>
struct OscillatorPropagatorT {
  T f0, f1;
  ::gmasim::physics::Mask<T> valid;
};

// One doubling where `at` holds: (C, S) of exp(N / 2), whose (N / 2)^2 = u_half I, to those of
// exp(N) = exp(N / 2)^2 = (C^2 + u_half S^2) I + (C S) N.
template <class T>
GMASIM_LAW_INLINE void oscillator_series_doubled(T u_half, ::gmasim::physics::Mask<T> at, T& C,
                                                 T& S) {
  const T c = C;
  C = select(at, c * c + u_half * (S * S), c);
  S = select(at, c * S, S);
}
// decay: the last e^(tau/2) taken by std::exp (physics::exp_cached; a run's step repeats it).
// valid is false (f0, f1 unset) beyond the series' caps.
template <class T>
GMASIM_LAW_INLINE OscillatorPropagatorT<T> oscillator_propagator(T tau, T delta,
                                                                 ExpPointT<T>& decay) {
  const T half_tau = 0.5 * tau;
  const T u = half_tau * half_tau - delta;
  const T au = abs(u);
  const ::gmasim::physics::Mask<T> valid =
      au <= 4.0 || (u < 0.0 && au <= ::gmasim::physics::kOscillatorSeriesUnder);
  OscillatorPropagatorT<T> p{0.0, 0.0, valid};
  if (none(valid)) return p;
  // The halvings of each valid lane: none where |u| <= 1/4, one (u / 4) to |u| = 1, two (u / 16)
  // to 4, ... (exact: powers of two); `level` counts them.
  T us = u, level = 0.0;
  int halvings = 0;  // the most of any lane
  for (::gmasim::physics::Mask<T> more = valid && au > 0.25; any(more);
       more = more && abs(us) > 0.25, ++halvings) {
    us = select(more, 0.25 * us, us);
    level = select(more, level + 1.0, level);
  }
  T C = polynomial7(us, ::gmasim::physics::kOscillatorCos),
    S = polynomial7(us, ::gmasim::physics::kOscillatorSinc);
  // exp(N / 2^j) to exp(N / 2^(j-1)), j = halvings .. 1: (N / 2^j)^2 = u / 4^j
  T u_half = us;
  for (int j = halvings; j >= 1; --j) {
    const ::gmasim::physics::Mask<T> at = level >= static_cast<double>(j);
    oscillator_series_doubled(u_half, at, C, S);
    u_half = select(at, 4.0 * u_half, u_half);
  }
  const ::gmasim::physics::Mask<T> short_tau = abs(half_tau) <= 1.0 / 64;
  T E;
  if (all(short_tau)) {
    E = exp_series7(half_tau);
  } else {
    const T cached = exp_cached(half_tau, decay, valid && !short_tau);
    E = none(short_tau) ? cached : select(short_tau, exp_series7(half_tau), cached);
  }
  p.f0 = E * (C - half_tau * S);
  p.f1 = E * S;
  return p;
}

// Exact update of one diagonal row of eq. (15),  m x'' + c x' + k x = F(t),
// over a step h with F linear from F0 to F1 (first-order hold) and m, c, k
// frozen over the step. The homogeneous part is propagated with its closed-form
// solution (under-, critically or over-damped; by its series where the step is
// short against the row's period: oscillator_propagator), the ramp by its
// particular solution, so the update is exact for piecewise-linear forcing and
// unconditionally stable: the step is not limited by the 7-20 kHz mechanical
// modes. Updates x [m] and v [m/s].
// inv_m = 1/m; decay: oscillator_propagator's (the row's last e^(tau/2)).
template <class T>
GMASIM_LAW_INLINE void oscillator_step(T m, T inv_m, T c, T k, T F0, T F1, T h, T& x, T& v,
                                       ExpPointT<T>& decay) {
  const T g = (F1 - F0) / h;  // force rate [N/s]
  // Particular solution x_p(s) = (F0 + g s)/k - g c / k^2, v_p = g / k.
  const T inv_k = 1.0 / k;
  const T xp0 = (F0 - g * c * inv_k) * inv_k;
  const T vp = g * inv_k;
  const T e0 = x - xp0;
  const T ed0 = v - vp;
  T e1 = 0.0, ed1 = 0.0;
  const T c_m = c * inv_m, k_m = k * inv_m;
  const OscillatorPropagatorT<T> pr = oscillator_propagator(-c_m * h, k_m * h * h, decay);
  if (any(pr.valid)) [[likely]] {
    e1 = pr.f0 * e0 + pr.f1 * h * ed0;
    ed1 = pr.f0 * ed0 - pr.f1 * h * (k_m * e0 + c_m * ed0);
  }
  if (!all(pr.valid)) oscillator_free_closed_form_where(!pr.valid, m, c, k, h, e0, ed0, e1, ed1);
  const T xp1 = (F1 - g * c * inv_k) * inv_k;
  x = xp1 + e1;
  v = vp + ed1;
}

// A base-excited row, m z'' + c (z' - q') + k (z - q) = 0, with its base q moving linearly from
// q0 to q1 over h (the sensor mount: model.hpp, SensorMountModel): the forcing c q' + k q is
// linear over the step, so oscillator_step is exact.
template <class T>
GMASIM_LAW_INLINE void base_excited_step(T m, T inv_m, T c, T k, T q0, T q1, T h, T& z, T& zv,
                                         ExpPointT<T>& decay) {
  const T qdot = (q1 - q0) / h;
  oscillator_step(m, inv_m, c, k, c * qdot + k * q0, c * qdot + k * q1, h, z, zv, decay);
}

// M-independent parts of eq. (13), fixed by stress and temperature (precomputed once
// per Conditions):
//   u = (sigma - sigma0)/sigma_lambda
//   rotation_compliance = 3 lambda_s / (4 sigma_lambda) sech^2 u               [1/Pa]
//   coupling = (3 lambda_s / 2)(1 - tanh u) + 2 beta dT                         [-]
// Over the number type T (gmasim/physics/number.hpp): DeltaETerms for one rod, a vector of them
// in the lanes.
template <class T>
struct DeltaETermsT {
  T inverse_Es_per_Pa;  // 1/E_s, the saturated (M = M_s) modulus
  T rotation_compliance_per_Pa;
  T coupling;
  T mu0_Ms2_over_chi_m_J_per_m3;  // mu0 pi M_s^T/(2k) = mu0 (M_s^T)^2 / chi_m (eq. 5)
  T S_J_per_m3;                   // stress_energy_term(), as in eq. (3)
};

// Eq. (13): Delta-E modulus E_G^{M,T,sigma} [Pa] at reduced magnetisation m = M/M_s^T.
//   1/E = 1/E_s + rot (1 - m^2) + coupling^2 m^2 / [mu0 Ms^2/chi_m sec^2(pi m/2) - S]
// The last term is evaluated multiplied through by cos^2(pi m/2), so that m = 1 (where
// sec^2 is infinite) gives E = E_s exactly; cos(pi m/2) by its series (cos_half_pi).
// delta_e_compliance is 1/E, the bracket itself (the step multiplies by it where eq. 11-12 and
// 17 divide by E).
template <class T>
GMASIM_LAW_INLINE T delta_e_compliance(T m, const DeltaETermsT<T>& d) {
  const T c = cos_half_pi(m);
  const T c2 = c * c;
  const T m2 = m * m;
  const T third =
      d.coupling * d.coupling * m2 * c2 / (d.mu0_Ms2_over_chi_m_J_per_m3 - c2 * d.S_J_per_m3);
  return d.inverse_Es_per_Pa + d.rotation_compliance_per_Pa * (1.0 - m2) + third;
}

// Eq. (12): saturation and maximum magnetostrictive stress [Pa].
template <class T>
GMASIM_LAW_INLINE T saturation_stress(T lambda_s, T E_Pa) {
  return 0.5 * lambda_s * E_Pa;
}
template <class T>
GMASIM_LAW_INLINE T maximum_stress(T lambda_s, T E_Pa) {
  return 1.5 * lambda_s * E_Pa;
}

// Eq. (11): prestress factor f(sigma_p) of lambda = f lambda_s m^2, with sigma_p the
// magnitude of the compressive prestress [Pa]:
//   f = 1 + 1/2 tanh(2 sigma_p / sigma_s)                          sigma_p <= sigma_s
//   f = (1 - (sigma_p - sigma_s)/sigma_max)(1 + 1/2 tanh(2 sigma_p/sigma_s))  otherwise
// tanh u from one exponential, sign(u) (1 - e^{-2|u|}) / (1 + e^{-2|u|}): its absolute error is
// a few 1e-16 (not its relative error near u = 0), all eq. (11) needs beside 1 (std::tanh goes
// through expm1, about three times the cost of exp).
template <class T>
GMASIM_LAW_INLINE T tanh_from_exp(T u, T e) {  // e = exp(-2|u|)
  const T t = (1.0 - e) / (1.0 + e);
  return select(u < 0.0, -t, t);
}

// The same with its exponential from an anchor nearby (p, exp_near: the step's last one).
template <class T>
GMASIM_LAW_INLINE T tanh_absolute_near(T u, ExpPointT<T>& p) {
  return tanh_from_exp(u, exp_near(-2.0 * abs(u), p));  // every lane evaluates it
}

// The factor at 2 sigma_p / sigma_s = two_sp_over_ss (given: the step forms it from 1/E).
// tanh_2sp_ss: tanh(2 sigma_p / sigma_s) (tanh_absolute).
template <class T>
GMASIM_LAW_INLINE T prestress_factor_from_tanh(T tanh_2sp_ss, T sigma_p_Pa, T sigma_s_Pa,
                                               T sigma_max_Pa) {
  const T base = 1.0 + 0.5 * tanh_2sp_ss;
  const ::gmasim::physics::Mask<T> below = sigma_p_Pa <= sigma_s_Pa;
  if (all(below)) return base;
  return select(below, base, (1.0 - (sigma_p_Pa - sigma_s_Pa) / sigma_max_Pa) * base);
}

// Eq. (11)-(12): magnetostrictive strain [-] with the stress thresholds of eq. (12)
// taken at the current modulus E_G; inv_E_per_Pa = 1/E_G (delta_e_compliance), so that
// 2 sigma_p / sigma_s = (4 sigma_p / lambda_s) / E_G is a product; four_sp_over_ls = 4 sigma_p /
// lambda_s, formed once (4.0 * sigma_p / lambda_s).
// The step's: tanh's exponential from the anchor `near` (tanh_absolute_near; RodState::
// prestress_exp), a few units in the last place from magnetostriction's.
template <class T>
GMASIM_LAW_INLINE T magnetostriction_near(T m, T lambda_s, T sigma_p_Pa, T four_sp_over_ls, T E_Pa,
                                          T inv_E_per_Pa, ExpPointT<T>& near) {
  const T f = prestress_factor_from_tanh(tanh_absolute_near(four_sp_over_ls * inv_E_per_Pa, near),
                                         sigma_p_Pa, saturation_stress(lambda_s, E_Pa),
                                         maximum_stress(lambda_s, E_Pa));
  return f * lambda_s * m * m;
}

// Eq. (14): magnetostrictive force of one rod [N].  F = lambda E A.
template <class T>
GMASIM_LAW_INLINE T rod_force(T lambda, T E_Pa, T area_m2) {
  return lambda * E_Pa * area_m2;
}

// Eq. (11)-(14) and (17) for one rod at its magnetisation M [A/m]: the Delta-E modulus, the
// magnetostriction (its tanh's exponential from the rod's anchor `prestress`), the force, the
// axial stiffness E A / l and the compliance 1/k_rod = (1/E)(l / A) the load chains sum
// (eq. 18). four_sp_over_ls = 4 sigma_p / lambda_s (magnetostriction_near). inv_MsT_E = 1/M_s^T of
// eq. (13), inv_Ms_strain = 1/M_s of eq. (11).
// joint_compliance_m_per_N = c_j, the rod's bonded joints in series with it (options.
// joint_mechanics; 0: rigid, and every result is eq. 14 and 17's bit for bit): the rod and its
// joints are one element of free stroke lambda l, compliance l / (E A) + c_j, so its stiffness
// and its blocked force are eq. (17)'s and eq. (14)'s times s = 1 / (1 + k_rod c_j).
template <class T>
struct RodMechanicsT {
  T E_Pa, lambda, F_N, k_rod_N_per_m, compliance_m_per_N;
};
template <class T>
GMASIM_LAW_INLINE RodMechanicsT<T> rod_mechanics(
    T M_A_per_m, T inv_MsT_E, const DeltaETermsT<T>& dE, T inv_Ms_strain, T lambda_s, T sigma_p_Pa,
    T four_sp_over_ls, T area_m2, T area_over_length_m, T length_over_area_per_m,
    T joint_compliance_m_per_N, ExpPointT<T>& prestress) {
  const T inv_E = delta_e_compliance(M_A_per_m * inv_MsT_E, dE);
  RodMechanicsT<T> r;
  r.E_Pa = 1.0 / inv_E;  // eq. (13)
  r.lambda = magnetostriction_near(M_A_per_m * inv_Ms_strain, lambda_s, sigma_p_Pa, four_sp_over_ls,
                                   r.E_Pa, inv_E, prestress);  // eq. (11)-(12)
  const T k_rod = r.E_Pa * area_over_length_m;                 // eq. (17): E A / l
  const T s = 1.0 / (1.0 + k_rod * joint_compliance_m_per_N);  // the joints' share (1 if rigid)
  r.F_N = rod_force(r.lambda, r.E_Pa, area_m2) * s;            // eq. (14)
  r.k_rod_N_per_m = k_rod * s;
  r.compliance_m_per_N = inv_E * length_over_area_per_m + joint_compliance_m_per_N;
  return r;
}

// Eq. (18) over the number type T (gmasim/physics/number.hpp): a rod's load stiffness from the
// compliance of its chain's fixed members and those of the rods in its chain (compliances[j],
// 1/k_rod of rod j; members: the chain's rod indices).
template <class T>
GMASIM_LAW_INLINE T chain_stiffness(T fixed_compliance_m_per_N, const T* compliances_m_per_N,
                                    const int* members, int count) {
  T inv_k = fixed_compliance_m_per_N;
  for (int j = 0; j < count; ++j) inv_k = inv_k + compliances_m_per_N[members[j]];
  return 1.0 / inv_k;
}

// Eq. (16): the oscillator's stiffness over a step, the mean of its values at the ends (the
// Delta-E effect varies it; the mean keeps the update second order in h).
template <class T>
GMASIM_LAW_INLINE T mid_step_stiffness(T K0_N_per_m, T k_rod1_N_per_m, T k_load1_N_per_m) {
  return 0.5 * (K0_N_per_m + k_rod1_N_per_m + k_load1_N_per_m);
}
