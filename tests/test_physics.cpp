// Analytic limits and finite-difference checks of the paper's laws (physics/ headers).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "gmasim/physics/jiles_atherton.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/physics/magnetostriction.hpp"
#include "gmasim/physics/mechanics.hpp"

using namespace gmasim::physics;

TEST(Langevin, DerivativeMatchesFiniteDifference) {
  // Central differences, h = 1e-5: truncation ~1e-11; observed max error 1.5e-11.
  for (double x :
       {-30.0, -5.0, -1.0, -0.02, -0.009, -1e-4, 0.0, 3e-3, 0.011, 0.5, 2.0, 19.0, 25.0}) {
    const double h = 1e-5;
    const double fd = (langevin(x + h) - langevin(x - h)) / (2 * h);
    EXPECT_NEAR(langevin_derivative(x), fd, 2e-10) << "x = " << x;
  }
}

TEST(Langevin, SeriesBranchIsContinuous) {
  // The small-|x| series and the closed form agree at the switch point 1e-2.
  const double x = 1e-2;
  const double closed = 1.0 / std::tanh(x) - 1.0 / x;
  EXPECT_NEAR(langevin(x), closed, 1e-13);
  EXPECT_NEAR(langevin(20.0), 1.0 / std::tanh(20.0) - 1.0 / 20.0, 1e-15);
}

TEST(JilesAtherton, AnhystereticLimitReversibleOnly) {
  // c = 1 and alpha = 0: eq. (9) reduces to M = M_an(H) = Ms L(H/a) exactly, whatever k.
  const JaCoefficients p{6000.0, 0.0, 1.0, 3000.0};
  const double Ms = 7.65e5;
  double Mirr = 0.0, M = 0.0, H = 0.0;
  for (int i = 1; i <= 400; ++i) {
    const double H1 = 200.0 * i * (i % 50 < 25 ? 1.0 : 0.7);
    ja_step(H, H1, Ms, p, Mirr, M);
    H = H1;
    EXPECT_NEAR(M, anhysteretic(H, Ms, p.a_A_per_m), 1e-9 * Ms);
  }
}

TEST(JilesAtherton, VanishingPinningFollowsAnhysteretic) {
  // k -> 0: the irreversible magnetisation relaxes onto M_an (no hysteresis). With
  // alpha != 0 the anhysteretic is the implicit M = Ms L((H + alpha M)/a).
  const JaCoefficients p{6000.0, -0.03, 0.2, 1.0};
  const double Ms = 7.65e5;
  double Mirr = 0.0, M = 0.0, H = 0.0;
  double worst = 0.0;
  for (int i = 1; i <= 20000; ++i) {
    const double H1 = 60000.0 * std::sin(2 * kPi * i / 20000.0);
    ja_step(H, H1, Ms, p, Mirr, M);
    H = H1;
    // implicit anhysteretic M = Ms L((H + alpha M)/a), by bisection (monotone: alpha < 0)
    double lo = -Ms, hi = Ms;
    for (int k = 0; k < 200; ++k) {
      const double mid = 0.5 * (lo + hi);
      (mid - anhysteretic(H + p.alpha * mid, Ms, p.a_A_per_m) > 0 ? hi : lo) = mid;
    }
    const double Ma = 0.5 * (lo + hi);
    worst = std::max(worst, std::fabs(M - Ma) / Ms);
  }
  EXPECT_LT(worst, 2e-4);  // observed 2.0e-5 (lag of order k dM/dH / Ms)
}

TEST(JilesAtherton, HysteresisLoopIsClosedAndOrdered) {
  // A symmetric cycle: descending branch lies above the ascending one (positive loop area).
  const JaCoefficients p{5947.0, -0.0377, 0.0464, 3032.0};
  const double Ms = 7.65e5;
  const int n = 4000;
  // At H = 0 on the way down (i = n/2) M > 0 (remanence); on the way up (i = n) M < 0.
  double Mirr = 0.0, M = 0.0, H = 0.0;
  double M_down0 = 0.0, M_up0 = 0.0;
  for (int cycle = 0; cycle < 3; ++cycle)
    for (int i = 1; i <= n; ++i) {
      const double H1 = 50000.0 * std::sin(2 * kPi * i / n);
      ja_step(H, H1, Ms, p, Mirr, M);
      H = H1;
      if (cycle == 2 && i == n / 2) M_down0 = M;
      if (cycle == 2 && i == n) M_up0 = M;
    }
  EXPECT_GT(M_down0, 1000.0);
  EXPECT_LT(M_up0, -1000.0);
  EXPECT_NEAR(M_down0, -M_up0, 1e-3 * Ms);  // symmetric loop
}

TEST(Permeability, TanAnhystereticLimitAndStress) {
  // Eq. (3) without stress: mu = mu0 (1 + chi_m cos^2(pi m/2)); at m = 0, mu_r = 1 + chi_m.
  EXPECT_NEAR(permeability(inverse_susceptibility(0.0, 19.84, 0.0, 7.65e5)) / kMu0, 20.84, 1e-12);
  const double m = 0.4, c = std::cos(0.5 * kPi * m);
  EXPECT_NEAR(permeability(inverse_susceptibility(m, 19.84, 0.0, 7.65e5)) / kMu0,
              1.0 + 19.84 * c * c, 1e-12);
  // Compression (sigma < 0) lowers the susceptibility: S < 0 raises 1/chi.
  const double L0 = Lambda0(-10e6, 1e-3, 22e6);
  const double S = stress_energy_term(-10e6, 1e-3, L0, 0.0, 0.0);
  EXPECT_LT(S, 0.0);
  EXPECT_GT(inverse_susceptibility(0.0, 19.84, S, 7.65e5), 1.0 / 19.84);
}

TEST(Permeability, Lambda0DerivativeIsTheDomainRotationStrain) {
  // d Lambda0/d sigma = lambda_s/4 + (3 lambda_s/4) tanh((sigma - sigma0)/sigma_l); FD check.
  const double ls = 1e-3, sl = 22e6;
  for (double s : {-60e6, -10e6, 0.0, 5e6, 40e6}) {
    const double h = 1e3;
    const double fd = (Lambda0(s + h, ls, sl) - Lambda0(s - h, ls, sl)) / (2 * h);
    const double an = 0.25 * ls + 0.75 * ls * std::tanh((s - sigma0_of(sl)) / sl);
    EXPECT_NEAR(fd, an, 1e-12) << s;
  }
  // lambda_0 rises to 1.5 lambda_s... its limit slope under strong compression is -lambda_s/2.
  EXPECT_NEAR((Lambda0(-500e6, ls, sl) - Lambda0(-500e6 - 1e3, ls, sl)) / 1e3, -0.5 * ls, 1e-9);
}

TEST(DeltaE, Eq13LimitsAtZeroAndFullMagnetisation) {
  const double Es = 110e9, ls = 1e-3, sl = 22e6, sigma = -5.5e6, Ms = 7.65e5, chi = 19.84;
  const double S = stress_energy_term(sigma, ls, Lambda0(sigma, ls, sl), -1.1e-5, 30.0);
  const DeltaETerms d = delta_e_terms(Es, ls, sigma, sl, -1.1e-5, 30.0, Ms, chi, S);
  // m = 0: 1/E = 1/E_s + 3 lambda_s/(4 sigma_l) sech^2((sigma - sigma0)/sigma_l).
  const double u = (sigma - sigma0_of(sl)) / sl;
  const double E0 = 1.0 / (1.0 / Es + 3 * ls / (4 * sl) / (std::cosh(u) * std::cosh(u)));
  EXPECT_NEAR(delta_e_modulus(0.0, d), E0, 1e-6 * E0);
  // m = 1: both magnetisation terms vanish, E = E_s (the saturated modulus).
  EXPECT_NEAR(delta_e_modulus(1.0, d), Es, 1e-6 * Es);
  EXPECT_NEAR(delta_e_modulus(-1.0, d), Es, 1e-6 * Es);
  // Continuity towards m = 1.
  EXPECT_NEAR(delta_e_modulus(1.0 - 1e-7, d), Es, 1e-3 * Es);
}

TEST(Magnetostriction, PrestressFactorBranchesAreContinuous) {
  const double ss = 15e6, smax = 45e6;
  EXPECT_NEAR(prestress_factor(ss, ss, smax), prestress_factor(ss * (1 + 1e-12), ss, smax), 1e-9);
  EXPECT_DOUBLE_EQ(prestress_factor(0.0, ss, smax), 1.0);
  // lambda scales with m^2 (eq. 11).
  EXPECT_NEAR(magnetostriction(0.5, 1e-3, 5e6, 30e9) / magnetostriction(1.0, 1e-3, 5e6, 30e9), 0.25,
              1e-15);
  EXPECT_DOUBLE_EQ(rod_force(1e-3, 30e9, 1e-4), 3000.0);
}

TEST(EddyLag, FirstOrderStepResponseTimeConstant) {
  // tau dH/dt = u - H: after one tau of a unit step, H = 1 - 1/e (exact update).
  const double tau = eddy_time_constant(20.84 * kMu0, 0.01, 0.0075, 1.07, 6e-7);
  EXPECT_NEAR(tau, 20.84 * kMu0 * (1e-4 - 0.5625e-4) / (4 * 1.07 * 6e-7), 1e-18);
  double H = 0.0;
  const int n = 1000;
  for (int i = 0; i < n; ++i) H = first_order_lag_step(H, 1.0, 1.0, tau / n, tau);
  EXPECT_NEAR(H, 1.0 - std::exp(-1.0), 1e-12);
  // A ramp u = t: steady lag of tau (H = t - tau + tau e^{-t/tau}).
  H = 0.0;
  const double h = tau / 37.0;
  for (int i = 0; i < 370; ++i) H = first_order_lag_step(H, i * h, (i + 1) * h, h, tau);
  const double t = 370 * h;
  EXPECT_NEAR(H, t - tau + tau * std::exp(-t / tau), 1e-12 * tau * 10);
}

TEST(Oscillator, StaticDeflectionIsForceOverStiffness) {
  const double m = 0.0746, c = 335.0, k = 137.3e6, F = 120.0;
  double x = 0.0, v = 0.0;
  for (int i = 0; i < 20000; ++i) oscillator_step(m, c, k, F, F, 5e-6, x, v);
  EXPECT_NEAR(x, F / k, 1e-12 * F / k);
  EXPECT_NEAR(v, 0.0, 1e-12);
}

TEST(Oscillator, ExactUpdateMatchesFineRk4) {
  // Under-, critically and over-damped, with a ramp force: the closed form at a coarse
  // step equals a fine RK4 integration (RK4 error ~1e-13 at this resolution).
  for (double zeta : {0.05, 1.0, 3.0}) {
    const double m = 0.03, k = 90e6, c = zeta * 2 * std::sqrt(k * m);
    const double h = 20e-6, F0 = 10.0, F1 = 50.0;
    double x = 1e-7, v = -2e-3;
    double xr = x, vr = v;
    oscillator_step(m, c, k, F0, F1, h, x, v);
    const int n = 20000;
    const double dt = h / n;
    auto acc = [&](double t, double xx, double vv) {
      return (F0 + (F1 - F0) * t / h - c * vv - k * xx) / m;
    };
    for (int i = 0; i < n; ++i) {
      const double t = i * dt;
      const double k1x = vr, k1v = acc(t, xr, vr);
      const double k2x = vr + 0.5 * dt * k1v,
                   k2v = acc(t + 0.5 * dt, xr + 0.5 * dt * k1x, vr + 0.5 * dt * k1v);
      const double k3x = vr + 0.5 * dt * k2v,
                   k3v = acc(t + 0.5 * dt, xr + 0.5 * dt * k2x, vr + 0.5 * dt * k2v);
      const double k4x = vr + dt * k3v, k4v = acc(t + dt, xr + dt * k3x, vr + dt * k3v);
      xr += dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
      vr += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
    EXPECT_NEAR(x, xr, 1e-12 * (std::fabs(xr) + 1e-7)) << "zeta " << zeta;
    EXPECT_NEAR(v, vr, 1e-9 * (std::fabs(vr) + 1e-3)) << "zeta " << zeta;
  }
}

TEST(Oscillator, SeriesPropagatorMatchesClosedForm) {
  // exp(A h) = f0 I + f1 A h of the free row: the series of oscillator_propagator against the
  // closed forms, f1 = e^(tau/2) sin(w h) / (w h), f0 = e^(tau/2) cos(w h) - tau/2 f1 with
  // (w h)^2 = delta - tau^2/4 (under-damped; sinh and cosh over-damped; f1 = e^(tau/2),
  // f0 = e^(tau/2) (1 - tau/2) critically damped), up to |w h|^2 = 4 (doubled once beyond 1/4,
  // twice beyond 1), with e^(tau/2) by its series (|tau/2| <= 1/64) and by std::exp (beyond);
  // observed worst 3.9e-16 (relative) to |w h|^2 = 1/4, 4.3e-15 beyond.
  double worst = 0.0, worst_doubled = 0.0;
  for (double wh : {1e-4, 0.01, 0.05, 0.1, 0.124, 0.2, 0.3, 0.45, 0.55, 0.8, 0.99, 1.2, 1.6, 1.99})
    for (double zeta : {0.0, 1e-3, 0.05, 0.3, 0.9, 1.0, 1.05, 3.0}) {
      const double tau = -2.0 * zeta * wh, delta = wh * wh;
      const OscillatorPropagator p = oscillator_propagator(tau, delta);
      if (!p.valid) continue;
      const double w2 = delta - 0.25 * tau * tau, w = std::sqrt(std::fabs(w2));
      const double sinc = w2 > 0 ? std::sin(w) / w : (w2 < 0 ? std::sinh(w) / w : 1.0);
      const double cosw = w2 > 0 ? std::cos(w) : std::cosh(w);
      const double f1 = std::exp(0.5 * tau) * sinc;
      const double f0 = std::exp(0.5 * tau) * cosw - 0.5 * tau * f1;
      const double err = std::max(std::fabs(p.f0 - f0) / std::fabs(f0), std::fabs(p.f1 - f1) / f1);
      (std::fabs(w2) <= 0.25 ? worst : worst_doubled) =
          std::max(std::fabs(w2) <= 0.25 ? worst : worst_doubled, err);
    }
  EXPECT_LT(worst, 4e-15);
  EXPECT_LT(worst_doubled, 4e-14);
  std::printf("propagator: %.3g, doubled %.3g\n", worst, worst_doubled);
  EXPECT_TRUE(oscillator_propagator(0.0, 0.3).valid);  // |u| = 0.3: doubled once
  EXPECT_TRUE(oscillator_propagator(0.0, 3.9).valid);  // doubled twice
  EXPECT_TRUE(oscillator_propagator(0.0, 4.1).valid);  // under-damped: doubled three times
  EXPECT_FALSE(oscillator_propagator(0.0, 1.01 * kOscillatorSeriesUnder).valid);  // closed form
  EXPECT_TRUE(oscillator_propagator(-4.0, 0.1).valid);    // over-damped, u = 3.9
  EXPECT_FALSE(oscillator_propagator(-10.0, 1.0).valid);  // over-damped, u = 24: closed form
}

// Steps of many of the row's periods (under-damped, |u| = (w_d h)^2 from 4 to the series' cap
// kOscillatorSeriesUnder: the identification's 200 steps a period at 10 Hz give w_d h ~ 40 for
// the MDMA's rods): the series at u / 4^n doubled n times (n = 2 .. 8) and the closed form
// (in double) against the closed form in long double, the error taken against e^(tau/2) (f0
// and w_d h f1 turn as cos and sin: either passes near zero). The doublings' rounding grows as
// 2^n, the closed form's as w_d h (its argument's rounding): observed series 2.9e-15 to w_d h =
// 10 and 5.6e-14 to the cap, the closed form 5.6e-16 and 1.7e-14.
TEST(Oscillator, LongStepsTakeTheSeriesToItsCap) {
  double worst_short = 0.0, worst = 0.0, worst_closed = 0.0;
  const double cap = std::sqrt(kOscillatorSeriesUnder);
  for (double wh : {2.01, 2.5, 3.7, 5.0, 7.9, 10.0, 17.3, 40.0, 41.3, 100.0, 200.0, cap})
    for (double zeta : {0.0, 1e-4, 1e-3, 0.01, 0.05}) {
      const double tau = -2.0 * zeta * wh, delta = wh * wh;
      const OscillatorPropagator p = oscillator_propagator(tau, delta);
      ASSERT_TRUE(p.valid) << "w h " << wh << ", zeta " << zeta;
      const long double w =
          std::sqrt(static_cast<long double>(delta) - 0.25L * static_cast<long double>(tau) * tau);
      const long double E = std::exp(0.5L * tau);
      const long double f1 = E * std::sin(w) / w, f0 = E * std::cos(w) - 0.5L * tau * f1;
      auto error = [&](double g0, double g1) {
        return static_cast<double>(std::max(std::fabs(g0 - f0), std::fabs(g1 - f1) * w) / E);
      };
      const double wd = std::sqrt(delta - 0.25 * tau * tau), Ed = std::exp(0.5 * tau);
      const double f1d = Ed * std::sin(wd) / wd;
      const double err = error(p.f0, p.f1);
      (wh <= 10.0 ? worst_short : worst) = std::max(wh <= 10.0 ? worst_short : worst, err);
      worst_closed = std::max(worst_closed, error(Ed * std::cos(wd) - 0.5 * tau * f1d, f1d));
    }
  EXPECT_LT(worst_short, 3e-14);
  EXPECT_LT(worst, 5e-13);
  EXPECT_FALSE(oscillator_propagator(0.0, 1.0001 * kOscillatorSeriesUnder).valid);
  std::printf("long steps: the series %.3g (w h <= 10), %.3g (to %g); the closed form %.3g\n",
              worst_short, worst, cap, worst_closed);
}

TEST(Oscillator, SeriesAndClosedFormAgreeAtTheirBorder) {
  // The free row (F = 0) stepped just inside and just beyond each border of the propagator's
  // series -- |u| = 1/4, 1, 4 and 16 (where it halves u once more) and kOscillatorSeriesUnder
  // (the closed form beyond) -- by oscillator_step and by the closed form at the same h: x and
  // v agree to rounding, against the row's amplitude (x and v / w_n turn as cos and sin: either
  // passes near zero). Observed 1.5e-15 to |u| = 16; at the cap (w_d h = 256, where each method
  // is off by ~1e-14: Oscillator.LongStepsTakeTheSeriesToItsCap) 9.9e-14.
  const double m = 0.0746, c = 335.0, k = 137.3e6, wn = std::sqrt(k / m);
  const double u_per_h2 = 0.25 * (c / m) * (c / m) - k / m;  // u / h^2 (under-damped: < 0)
  double worst = 0.0, worst_cap = 0.0;
  for (double border : {0.25, 1.0, 4.0, 16.0, kOscillatorSeriesUnder})
    for (double side : {1.0 - 1e-12, 1.0 + 1e-12}) {
      const double h = std::sqrt(border / -u_per_h2) * side;
      double x = 1e-7, v = -2e-3, xc = 0.0, vc = 0.0;
      oscillator_free_closed_form(m, c, k, h, x, v, xc, vc);
      oscillator_step(m, c, k, 0.0, 0.0, h, x, v);
      const double amplitude = std::hypot(xc, vc / wn);
      const double e = std::max(std::fabs(x - xc), std::fabs(v - vc) / wn) / amplitude;
      (border < 100.0 ? worst : worst_cap) = std::max(border < 100.0 ? worst : worst_cap, e);
    }
  EXPECT_LT(worst, 2e-14);
  EXPECT_LT(worst_cap, 1e-12);
  std::printf("series against the closed form at the borders: %.3g; at the cap %.3g\n", worst,
              worst_cap);
}

TEST(Mechanics, SeriesAndSleeveLaws) {
  const std::vector<double> k{2.0, 2.0};
  EXPECT_DOUBLE_EQ(series_combination(k), 1.0);
  const std::vector<double> l{0.004, 0.03, 0.004}, a{60e-6, 27.178e-6, 60e-6};
  // Table 6: k_t1 = 156 N/um at 20 degC with E_t^T = 193 GPa.
  const double Et = sleeve_modulus(195.1334e9, 0.10667e9, 20.0);
  EXPECT_NEAR(Et, 193.0e9, 1e6);
  EXPECT_NEAR(sleeve_stiffness(Et, l, a), 156e6, 0.01 * 156e6);
  // Eq. (21) with the model file's lengths gives the paper's 0.662 um/degC.
  EXPECT_NEAR(
      thermal_expansion(12.9e-6 * 0.09, 12.2e-6 * 0.012, 12.2e-6 * 0.02, 17.2e-6 * 0.05171, 1.0),
      0.662e-6, 1e-10);
}

TEST(PermanentMagnet, Eq1) {
  EXPECT_DOUBLE_EQ(pm_mmf(2520.0, 0.0, 0.0, 50.0), 2520.0);
  EXPECT_NEAR(pm_mmf(2520.0, -3e-4, 1e-7, 50.0), 2520.0 * (1 - 0.015 + 2.5e-4), 1e-9);
  EXPECT_NEAR(saturation_magnetisation(7.65e5, 50.0, 360.0, 0.001),
              7.65e5 * std::pow(1 - 50.0 / 360.0, 0.001), 1e-9);
  EXPECT_NEAR(resistivity(6e-7, 2.5e-9, 50.0), 6e-7 + 1.25e-7, 1e-20);
}

// Units in the last place between a and b (b's ulp).
static double ulps(double a, double b) {
  return std::fabs(a - b) / (std::nextafter(std::fabs(b), INFINITY) - std::fabs(b));
}

TEST(Series, ExpNearIsWithinAFewUlp) {
  // exp_near against std::exp along walks of the exponent (the Langevin function's -2|x| and the
  // lag's -r move like this from one Newton iterate and one step to the next), the anchor kept
  // over the whole walk: every value is one series and one product from a std::exp value, so the
  // error must not grow with the walk's length. Observed worst 2 ulp over 2.1e5 values (and over
  // 2e6 random anchor/exponent pairs |y - y_a| <= 1/8).
  double worst = 0.0;
  long anchored = 0;
  for (double y0 : {-40.0, -7.3, -1.0, -0.01, 0.0, 0.3, 5.0}) {
    ExpPoint a = kNoExpPoint;
    double y = y0;
    for (int k = 0; k < 30000; ++k) {
      y += 0.003 * std::sin(0.001 * k) + (k % 97 == 0 ? 0.11 : 0.0);
      const double y_before = a.y;
      worst = std::max(worst, ulps(exp_near(y, a), std::exp(y)));
      anchored += a.y == y_before;
    }
  }
  EXPECT_LE(worst, 4.0);
  EXPECT_GT(anchored, 150000);  // the anchor serves most evaluations (observed 206906 of 210000)
  for (double x : {-0.125, -0.01, 1e-9, 0.125})  // the series at its bounds: observed 0 ulp
    EXPECT_LE(ulps(1.0 + expm1_series10(x), std::exp(x)), 1.0) << "x = " << x;
}

TEST(Series, CosHalfPiMatchesStdCos) {
  // cos(pi m / 2) by its series on |m| <= 1 against std::cos: absolute error (the Delta-E term of
  // eq. 13 needs cos^2 beside O(1)); observed worst 2.9e-16. Outside |m| <= 1 it is std::cos.
  double worst = 0.0;
  for (int k = -20000; k <= 20000; ++k) {
    const double m = k / 20000.0;
    worst = std::max(worst, std::fabs(cos_half_pi(m) - std::cos(0.5 * kPi * m)));
  }
  EXPECT_LE(worst, 3e-15);
  EXPECT_EQ(cos_half_pi(1.25), std::cos(1.5707963267948966 * 1.25));
}
