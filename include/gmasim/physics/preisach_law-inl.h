// The Preisach law's evaluation (docs/model.md, "The Preisach law") over the number type T
// (gmasim/physics/number.hpp), written once: the third part of the step's laws (after
// laws-inl.h and ja_law-inl.h, whose conventions and langevin_pair it uses). No include guard
// and no #include: included inside a namespace, once per instance (gmasim/physics/laws.hpp for
// double: the scalar step's PreisachLaw; src/lanes/number_lanes-inl.h per SIMD target: the
// Preisach lanes). The extrema stack is scalar code (gmasim/physics/preisach_history.hpp): the
// law reads the stack a move continues from through preisach_base_at, one stack per lane.
//
// The transcendentals. The Everett function needs erfc and exp at every bin edge of every Newton
// iterate (18 of each per iterate), so the lanes cannot afford libm lane by lane here (as the
// Jiles-Atherton law does with its one exponential): erfc and exp are written below over T in
// + - * / and exact primitives (pow2i, table_at), and the scalar instance runs the same
// algorithm. A lane is therefore the scalar step bit for bit, and no SIMD target differs (no FMA:
// the library is built with -ffp-contract=off). Both are within a few units in the last place
// (tests/test_preisach.cpp holds them against the C library's in long double).

// exp(x) for x <= 0 (the law's arguments; 0 below -745.2, where exp underflows), table-driven as
// in Tang, ACM TOMS 15 (1989) 144: x = (32 n + j) ln2/32 + r, |r| <= ln2/64, exp(x) =
// 2^n 2^(j/32) e^r with 2^(j/32) from a table of 32 correctly rounded doubles (literals, computed
// to 50 digits: no libm of the build machine enters), ln2/32 split in a high part of 32 bits
// (k ln2_hi/32 is exact) and the rest (fdlibm's split of ln2), e^r by its Taylor polynomial to
// r^6 (truncation 0.011^7/7! = 4e-18 relative), and the scaling 2^n in two exact halves (2^n
// itself would leave the normal range below n = -1022; the product rounds once).
// The integer nearest v (ties to even) for |v| < 2^51, by adding and subtracting 1.5 * 2^52:
// two IEEE additions (not folded: the library is built without -ffast-math), the same in every
// instance, and no conversion.
template <class T>
GMASIM_LAW_INLINE T round_even(T v) {
  constexpr double kMagic = 6755399441055744.0;
  return (v + kMagic) - kMagic;
}

template <class T>
GMASIM_LAW_INLINE T exp_nonpositive(T x) {
  static constexpr double kTwoToJOver32[32] = {1.0,
                                               1.0218971486541166,
                                               1.0442737824274138,
                                               1.0671404006768237,
                                               1.0905077326652577,
                                               1.1143867425958924,
                                               1.1387886347566916,
                                               1.1637248587775775,
                                               1.189207115002721,
                                               1.215247359980469,
                                               1.241857812073484,
                                               1.2690509571917332,
                                               1.2968395546510096,
                                               1.3252366431597413,
                                               1.3542555469368927,
                                               1.383909881963832,
                                               1.4142135623730951,
                                               1.4451808069770467,
                                               1.4768261459394993,
                                               1.5091644275934228,
                                               1.5422108254079407,
                                               1.5759808451078865,
                                               1.6104903319492543,
                                               1.645755478153965,
                                               1.681792830507429,
                                               1.718619298122478,
                                               1.7562521603732995,
                                               1.7947090750031072,
                                               1.8340080864093424,
                                               1.8741676341103,
                                               1.9152065613971474,
                                               1.9571441241754002};
  constexpr double kLn2Hi = 6.93147180369123816490e-01, kLn2Lo = 1.90821492927058770002e-10;
  // the table's index and 2^n stay in range for every x: clamped to [-745.2, 709] (a NaN to the
  // lower end, then given back as NaN)
  const ::gmasim::physics::Mask<T> under = x < T(-745.2), number = x == x;
  const T xc = select(x >= T(-745.2), select(x <= T(709.0), x, T(709.0)), T(-745.2));
  const T k = round_even(xc * 46.166241308446828);      // 32 / ln2
  const T n = round_even(k * (1.0 / 32.0) - 0.484375);  // floor(k / 32): k / 32 - 15.5 / 32
  const T j = k - n * 32.0;                             // 0 .. 31
  const T r = (xc - k * (kLn2Hi / 32.0)) - k * (kLn2Lo / 32.0);
  // Horner, written out (a loop over the coefficients kept p in a general register)
  const T p =
      ((((((1.0 / 720.0) * r + 1.0 / 120.0) * r + 1.0 / 24.0) * r + 1.0 / 6.0) * r + 0.5) * r +
       1.0) *
          r +
      1.0;
  const T n1 = round_even(n * 0.5 - 0.25);  // floor(n / 2)
  const T e = ((table_at(kTwoToJOver32, j) * p) * pow2i(n1)) * pow2i(n - n1);
  return select(number, select(under, T(0.0), e), x);
}

// num = (num + p[i]) x and den = (den + q[i]) x for i = 0 .. N - 1: the Horner steps of a
// rational function's numerator and denominator, unrolled at compile time (a fold over I).
template <std::size_t... I, class T>
GMASIM_LAW_INLINE void horner_steps(std::index_sequence<I...>, T& num, T& den, T x, const double* p,
                                    const double* q) {
  ((num = (num + p[I]) * x, den = (den + q[I]) * x), ...);
}

// erfc(x) after W. J. Cody, "Rational Chebyshev approximations for the error function", Math.
// Comp. 23 (1969) 631-637 (the double-precision coefficients of his specfun routine CALERF,
// netlib): |x| <= 0.46875: 1 - x R1(x^2); 0.46875 < |x| <= 4: exp(-x^2) R2(|x|); |x| > 4:
// exp(-x^2) (1/sqrt(pi) - R3(1/x^2) / x^2) / |x|; exp(-x^2) as exp(-t^2) exp(-(|x| - t)(|x| + t))
// with t = |x| truncated to 1/16 (no rounding of x^2 enters the exponent; exp(-t^2) from a table
// over that grid: physics::exp_minus_grid_squared); 0 beyond |x| = 26.543
// (below the smallest double); erfc(-|x|) = 2 - erfc(|x|). gauss receives exp(-x^2) (that
// product; 0 beyond 26.543), which the Gaussian density shares. Each branch is evaluated only
// where a lane needs it.
template <class T>
GMASIM_LAW_INLINE T erfc_cody(T x, T& gauss,
                              const double* grid = ::gmasim::physics::exp_minus_grid_squared()) {
  constexpr double a[5] = {3.16112374387056560e00, 1.13864154151050156e02, 3.77485237685302021e02,
                           3.20937758913846947e03, 1.85777706184603153e-1};
  constexpr double b[4] = {2.36012909523441209e01, 2.44024637934444173e02, 1.28261652607737228e03,
                           2.84423683343917062e03};
  constexpr double c[9] = {5.64188496988670089e-1, 8.88314979438837594e00, 6.61191906371416295e01,
                           2.98635138197400131e02, 8.81952221241769090e02, 1.71204761263407058e03,
                           2.05107837782607147e03, 1.23033935479799725e03, 2.15311535474403846e-8};
  constexpr double dd[8] = {1.57449261107098347e01, 1.17693950891312499e02, 5.37181101862009858e02,
                            1.62138957456669019e03, 3.29079923573345963e03, 4.36261909014324716e03,
                            3.43936767414372164e03, 1.23033935480374942e03};
  constexpr double p[6] = {3.05326634961232344e-1, 3.60344899949804439e-1, 1.25781726111229246e-1,
                           1.60837851487422766e-2, 6.58749161529837803e-4, 1.63153871373020978e-2};
  constexpr double q[5] = {2.56852019228982242e00, 1.87295284992346047e00, 5.27905102951428412e-1,
                           6.05183413124413191e-2, 2.33520497626869185e-3};
  constexpr double kRsqrtPi = 5.6418958354775628695e-1, kCap = 26.543;
  const T ax = abs(x);
  const T y = select(ax <= T(kCap), ax, T(kCap));  // a NaN to the cap (the table's index in
                                                   // range), given back as NaN below
  const T ysq = y * y;
  const ::gmasim::physics::Mask<T> is_small = y <= T(0.46875), is_mid = y <= T(4.0);
  T small = 1.0, mid = 1.0, tail = 1.0;
  if (any(is_small)) {  // |x| <= 0.46875
    T num = a[4] * ysq, den = ysq;
    horner_steps(std::make_index_sequence<3>{}, num, den, ysq, a, b);
    small = 1.0 - (x * (num + a[3])) / (den + b[3]);
  }
  if (any(!is_small && is_mid)) {  // 0.46875 < |x| <= 4
    T num = c[8] * y, den = y;
    horner_steps(std::make_index_sequence<7>{}, num, den, y, c, dd);
    mid = (num + c[7]) / (den + dd[7]);
  }
  if (!all(is_mid)) {  // |x| > 4
    const T z = 1.0 / ysq;
    T num = p[5] * z, den = z;
    horner_steps(std::make_index_sequence<4>{}, num, den, z, p, q);
    tail = (kRsqrtPi - (z * (num + p[4])) / (den + q[4])) / y;
  }
  // t <= y on the grid of 1/16 (floor(16 y), or one below where 16 y is an even integer's
  // neighbour tie: any such t keeps t^2 exact and del >= 0)
  const T m = round_even(y * 16.0 - 0.5);
  const T t = m * (1.0 / 16.0);
  const T del = (y - t) * (y + t);
  // exp(-t^2) from the grid's table (exp_nonpositive's values, made once), exp(-del) computed
  gauss = select(y >= T(kCap), T(0.0), table_at(grid, m) * exp_nonpositive(-del));
  T big = gauss * select(is_mid, mid, tail);
  big = select(x < T(0.0), 2.0 - big, big);
  const ::gmasim::physics::Mask<T> number = x == x;
  gauss = select(number, gauss, x);
  return select(number, select(is_small, small, big), x);
}

// The Gaussian f_u of standard deviation s at y, its CDF F, A = int F and Y = int y F(y) dy
// (B = int A); the density's exp(-y^2 / (2 s^2)) is the erfc's exp(-z^2), z = -y/(s sqrt 2).
template <class T>
struct GaussTermsT {
  T F, f, A, Y;
};
template <class T>
GMASIM_LAW_INLINE GaussTermsT<T> gauss_terms(
    T y, T s, const double* grid = ::gmasim::physics::exp_minus_grid_squared()) {
  constexpr double kSqrt2 = 1.4142135623730951, kSqrt2Pi = 2.5066282746310002;
  T gauss;
  const T F = 0.5 * erfc_cody(-y / (s * kSqrt2), gauss, grid);
  const T f = gauss / (s * kSqrt2Pi);
  const T s2 = s * s;
  const T A = y * F + s2 * f;
  const T B = (0.5 * (y * y + s2)) * F + (((0.5 * y) * s) * s) * f;
  return {F, f, A, y * A - B};
}

// The distribution in reduced units (PreisachDistribution's numbers, in T: each lane its own rod
// and temperature) and the law's constants at one temperature (PreisachCoefficients, M_s^T and
// the reciprocals the scalar law forms: inv_a = 1/a, inv_hc = 1/H_c).
template <class T>
struct PreisachBinsT {
  T s;                                           // std of h_u / H_c^T
  T edge[::gmasim::physics::kPreisachBins + 1];  // bin edges of h_c / H_c^T
  T density[::gmasim::physics::kPreisachBins];   // f_c on each bin
};
template <class T>
struct PreisachConstantsT {
  T MsT, c, alpha, a, inv_a, inv_hc;
  PreisachBinsT<T> bins;
};

// The triangle T(a, b) = {b <= beta <= alpha <= a} of the Preisach plane: its measure E (the
// Everett function), its moments in h_c and h_u, and dE/da, dE/db. a may be +inf, b -inf:
//   E(a, b) = int_0^D f_c(h) [F(a - h) - F(b + h)] dh,  D = (a - b)/2;  Ec with h f_c(h) in
//   place of f_c;  Eu = int_0^D f_c(h) s^2 [f(b + h) - f(a - h)] dh  (int u f(u) du = -s^2 f(u)).
// Each bin whose lower edge is below D counts, to min(upper edge, D). Side a over a bin [p, q]:
// {A(a-p) - A(a-q), a (A(a-p) - A(a-q)) - (Y(a-p) - Y(a-q)), F(a-p) - F(a-q)} (the integrals of
// F(a - h), h F(a - h) and f(a - h)); a = +inf makes it {q - p, (q^2 - p^2)/2, 0}. Side b alike
// with F(b + h) (nothing for b = -inf). The upper limit D (where a - h = b + h) adds nothing to
// the derivatives. A bin's upper Gaussian terms are the next bin's lower ones, so each edge is
// evaluated once. Nothing where a <= b.
template <class T>
struct EverettT {
  T E, Ec, Eu, dE_da, dE_db;
};
template <class T>
GMASIM_LAW_RARE EverettT<T> everett_bins(const PreisachBinsT<T>& k, T a, T b) {
  using MaskT = ::gmasim::physics::Mask<T>;
  constexpr double kInf = __builtin_inf();
  const T zero = 0.0, s = k.s;
  EverettT<T> e{zero, zero, zero, zero, zero};
  const MaskT a_inf = abs(a) == T(kInf), b_inf = abs(b) == T(kInf), valid = a > b;
  if (none(valid)) return e;
  const T Dl = select(a_inf || b_inf, T(kInf), 0.5 * (a - b));
  const T af = select(a_inf, zero, a), bf = select(b_inf, zero, b);
  const bool side_a = any(valid && !a_inf), side_b = any(valid && !b_inf);
  const double* grid = ::gmasim::physics::exp_minus_grid_squared();
  GaussTermsT<T> ga_p{zero, zero, zero, zero}, gb_p{zero, zero, zero, zero};
  if (side_a) ga_p = gauss_terms(af - k.edge[0], s, grid);
  if (side_b) gb_p = gauss_terms(bf + k.edge[0], s, grid);
  for (int j = 0; j < ::gmasim::physics::kPreisachBins; ++j) {
    const MaskT active = valid && k.edge[j] < Dl;
    if (none(active)) break;
    const T p = k.edge[j], q = select(k.edge[j + 1] < Dl, k.edge[j + 1], Dl), w = k.density[j];
    T I0a = q - p, I1a = 0.5 * (q * q - p * p), Ja = zero, I0b = zero, I1b = zero, Jb = zero;
    if (side_a) {
      const GaussTermsT<T> ga_q = gauss_terms(af - q, s, grid);
      const T dA = ga_p.A - ga_q.A;
      I0a = select(a_inf, I0a, dA);
      I1a = select(a_inf, I1a, af * dA - (ga_p.Y - ga_q.Y));
      Ja = select(a_inf, zero, ga_p.F - ga_q.F);
      ga_p = ga_q;
    }
    if (side_b) {
      const GaussTermsT<T> gb_q = gauss_terms(bf + q, s, grid);
      const T dA = gb_q.A - gb_p.A;
      I0b = select(b_inf, zero, dA);
      I1b = select(b_inf, zero, (gb_q.Y - gb_p.Y) - bf * dA);
      Jb = select(b_inf, zero, gb_q.F - gb_p.F);
      gb_p = gb_q;
    }
    e.E = e.E + select(active, w * (I0a - I0b), zero);
    e.Ec = e.Ec + select(active, w * (I1a - I1b), zero);
    e.Eu = e.Eu + select(active, ((w * s) * s) * (Jb - Ja), zero);
    e.dE_da = e.dE_da + select(active, w * Ja, zero);
    e.dE_db = e.dE_db - select(active, w * Jb, zero);
  }
  return e;
}

// The up-switched measure (and its moments, and d mu / dx along the move) at reduced input x,
// reached monotonically from a base extremum at xb with measure mub and moments mcb, mub_u
// (preisach_base's: up, the move rises; same, x is the stack's x_now and nothing moves): up,
// the triangle T(x, xb) switches up; down, T(xb, x) switches down.
template <class T>
struct PreisachPointT {
  T mu, mc, mu_u, dmu_dx;
};
template <class T>
GMASIM_LAW_INLINE PreisachPointT<T> preisach_point_from(const PreisachBinsT<T>& k, T xb, T mub,
                                                        T mcb, T mub_u,
                                                        ::gmasim::physics::Mask<T> up,
                                                        ::gmasim::physics::Mask<T> same, T x) {
  const T zero = 0.0;
  const EverettT<T> e =
      everett_bins(k, select(same, zero, select(up, x, xb)), select(same, zero, select(up, xb, x)));
  PreisachPointT<T> r;
  r.mu = select(same, mub, select(up, mub + e.E, mub - e.E));
  r.mc = select(same, mcb, select(up, mcb + e.Ec, mcb - e.Ec));
  r.mu_u = select(same, mub_u, select(up, mub_u + e.Eu, mub_u - e.Eu));
  r.dmu_dx = select(same, zero, select(up, e.dE_da, -e.dE_db));
  return r;
}

// The law of a rod: the hysterons' irreversible part, a reversible Langevin part and a mean
// field (Della Torre's moving model):
//   M = M_s^T [ (1 - c) (2 mu(x) - 1) + c L(H_e / a) ],  H_e = H + alpha M,  x = H_e / H_c^T.
// The end magnetisation of a move to field H1 from the stacks h (not committed), in the lanes of
// `todo`: Newton on g(M) = M - M_s^T [...] with its exact derivative, steps
// -g / max(1 - alpha chi_e, 0.2) (alpha > 0, positive feedback: damped), from M_guess; each lane
// stops where |g| <= 1e-12 M_s^T or at the 60th evaluation, with that evaluation's M, chi_e =
// M_s [(1 - c) 2 mu'(x) / H_c + c L'(H_e/a) / a], x and point.
template <class T>
struct PreisachSolveT {
  T M, chi_e, x1, mu, mc, mu_u;
};
template <class T>
GMASIM_LAW_INLINE PreisachSolveT<T> preisach_solve(::gmasim::physics::Mask<T> todo,
                                                   const PreisachConstantsT<T>& k,
                                                   const ::gmasim::physics::PreisachHistory* h,
                                                   T H1, T M_guess) {
  using MaskT = ::gmasim::physics::Mask<T>;
  const T tol = 1e-12 * k.MsT, one_c = 1.0 - k.c, zero = 0.0;
  PreisachSolveT<T> r{M_guess, zero, zero, zero, zero, zero};
  T M = M_guess;
  MaskT left = todo;
  for (int it = 0; it < 60 && any(left); ++it) {
    const T He = H1 + k.alpha * M;
    const T x = He * k.inv_hc;
    T xb, mub, mcb, mub_u;
    MaskT up, same;
    preisach_base_at(h, x, xb, mub, mcb, mub_u, up, same);
    const PreisachPointT<T> pt = preisach_point_from(k.bins, xb, mub, mcb, mub_u, up, same, x);
    const LangevinValueT<T> lv = langevin_pair(He * k.inv_a);
    const T Mnew = k.MsT * (one_c * (2.0 * pt.mu - 1.0) + k.c * lv.L);
    const T chi_e = k.MsT * (((one_c * 2.0) * pt.dmu_dx) * k.inv_hc + (k.c * lv.dL) * k.inv_a);
    const T g = M - Mnew;
    const MaskT stop = left && (it == 59 ? true_mask(g) : abs(g) <= tol);
    r.M = select(stop, Mnew, r.M);
    r.chi_e = select(stop, chi_e, r.chi_e);
    r.x1 = select(stop, x, r.x1);
    r.mu = select(stop, pt.mu, r.mu);
    r.mc = select(stop, pt.mc, r.mc);
    r.mu_u = select(stop, pt.mu_u, r.mu_u);
    left = left && !stop;
    T dg = 1.0 - k.alpha * chi_e;
    dg = select(dg < T(0.2), T(0.2), dg);
    M = select(left, M - g / dg, M);
  }
  return r;
}

// The slope at a reversal (the hysterons' part has zero slope there, E ~ (a - b)^2): the
// reversible part with the mean field, c M_s L'/a / (1 - alpha c M_s L'/a), at (H, M).
template <class T>
GMASIM_LAW_INLINE T preisach_reversible_slope(const PreisachConstantsT<T>& k, T H, T M) {
  const T chi_e = ((k.c * k.MsT) / k.a) * langevin_pair((H + k.alpha * M) / k.a).dL;
  return chi_e / (1.0 - k.alpha * chi_e);
}

// The law's trial of a move from (H0, M0) to H1 (PreisachLaw::trial_from; the lanes' joint
// trial): where H1 = H0 nothing moves and the slope is the reversible part's; elsewhere the
// solve from M_guess, its slope chi_e / (1 - alpha chi_e), and the point it ends at (x1 and the
// measure there, which the commit pushes without evaluating the distribution again).
template <class T>
struct PreisachTrialT {
  T M, dM_dH, x1, mu, mc, mu_u;
  ::gmasim::physics::Mask<T> moved;
};
template <class T>
GMASIM_LAW_INLINE PreisachTrialT<T> preisach_trial(const PreisachConstantsT<T>& k,
                                                   const ::gmasim::physics::PreisachHistory* h,
                                                   T H0, T M0, T H1, T M_guess) {
  const T zero = 0.0;
  PreisachTrialT<T> t{M0, zero, zero, zero, zero, zero, !(H1 == H0)};
  if (!all(t.moved)) t.dM_dH = preisach_reversible_slope(k, H0, M0);
  if (any(t.moved)) {
    const PreisachSolveT<T> s = preisach_solve(t.moved, k, h, H1, M_guess);
    t.M = select(t.moved, s.M, M0);
    t.dM_dH = select(t.moved, s.chi_e / (1.0 - k.alpha * s.chi_e), t.dM_dH);
    t.x1 = s.x1;
    t.mu = s.mu;
    t.mc = s.mc;
    t.mu_u = s.mu_u;
  }
  return t;
}
