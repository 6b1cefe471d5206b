// The frequency response (Fig. 15, src/experiments/frf.cpp): the stepped sine, the
// small-signal linearisation, the modes. Numbers, not plumbing; tolerances are about 10x the
// residual observed on this model (noted at each check).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "experiments_fixtures.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/compensate.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/reproduce.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/simulate.hpp"

using namespace gmasim;
using namespace gmasim_experiments_test;

// ---------------------------------------------------------------------------------------
// Frequency response
// ---------------------------------------------------------------------------------------
TEST(Frf, FirstHarmonicOfAKnownSignal) {
  const double f = 37.0;
  std::vector<double> t, y, i;
  const int n = 500;  // two whole periods
  for (int k = 0; k < n; ++k) {
    const double tk = 2.0 / f * k / n;
    t.push_back(tk);
    y.push_back(2.0 + 3.0 * std::sin(kTwoPi * f * tk + 0.5) + 0.3 * std::sin(3 * kTwoPi * f * tk));
    i.push_back(0.7 + std::sin(kTwoPi * f * tk));
  }
  const auto r = first_harmonic_ratio(t, y, i, f);
  EXPECT_NEAR(std::abs(r), 3.0, 1e-12);
  EXPECT_NEAR(std::arg(r), 0.5, 1e-12);
}

TEST(Frf, ResonanceAndBandwidthOfAnalyticCurves) {
  std::vector<double> f, lag, osc;
  const double fc = 300.0, fn = 2000.0, z = 0.1;
  for (int k = 0; k < 3000; ++k) {
    const double fr = std::pow(10.0, 4.0 * k / 2999.0);
    f.push_back(fr);
    lag.push_back(1.0 / std::sqrt(1.0 + (fr / fc) * (fr / fc)));
    const double u = fr / fn;
    osc.push_back(1.0 / std::sqrt((1 - u * u) * (1 - u * u) + (2 * z * u) * (2 * z * u)));
  }
  EXPECT_NEAR(find_bandwidth_3dB_Hz(f, lag), fc, 1e-3 * fc);
  EXPECT_EQ(find_resonance_Hz(f, lag), 0.0);  // monotone: no peak
  EXPECT_NEAR(find_resonance_Hz(f, osc), fn * std::sqrt(1 - 2 * z * z), 1e-3 * fn);
}

// The linearised model is the chain circuit -> eddy lag -> JA -> force -> mechanics of
// eq. (7), (9), (11)-(15); with the circuit's mu(M) feedback G and the cross-stiffness
// terms of D removed it must be exactly the analytic product of the eddy lag and the
// oscillator of each rod, and the full model must stay close to that (G is small).
TEST(Frf, LinearisationIsTheMechanicsTimesTheEddyLag) {
  const Model& m = mdma_printed();
  const Conditions c = make_conditions(m, 20.0);
  const State s = settle_at_bias(m, c, 1.0, BiasState::Anhysteretic);
  const SmallSignalModel L = linearise(m, c, s);
  ASSERT_EQ(L.n, 3);
  SmallSignalModel P = L;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      P.G[static_cast<std::size_t>(i * 3 + j)] = 0.0;
      if (i != j) P.D_N_per_A_per_m[static_cast<std::size_t>(i * 3 + j)] = 0.0;
    }
  for (double f : {0.0, 3.0, 150.0, 700.0, 2500.0, 6000.0, 12000.0}) {
    const std::complex<double> sj(0.0, kTwoPi * f);
    std::complex<double> Y = 0.0;
    for (std::size_t i = 0; i < 3; ++i) {
      const auto lag = 1.0 / (1.0 + L.tau_s[i] * sj);  // eq. (7)
      const auto osc = 1.0 / (L.mass_kg[i] * sj * sj + L.damping_N_s_per_m[i] * sj +
                              L.stiffness_N_per_m[i]);  // eq. (15)
      Y += L.g_A_per_m_per_A[i] * lag * L.chi[i] * L.D_N_per_A_per_m[i * 3 + i] * osc;
    }
    const auto Yp = P.response(f);
    EXPECT_NEAR(std::abs(Yp - Y), 0.0, 1e-12 * std::abs(Y)) << f << " Hz";
    // The couplings change the response by a few percent only (observed <= 6 %).
    EXPECT_LT(std::abs(L.response(f) - Y) / std::abs(Y), 0.15) << f << " Hz";
  }
  // The eddy time constants are eq. (7) at the bias permeability.
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& rc = c.rods[i];
    EXPECT_NEAR(L.tau_s[i],
                physics::eddy_time_constant(s.rods[i].mu_r * physics::kMu0, rc.r_outer_m,
                                            rc.r_inner_m, rc.k_j, rc.rho_ohm_m),
                1e-6 * L.tau_s[i]);
    EXPECT_GT(L.tau_s[i], 1e-4);
    EXPECT_LT(L.tau_s[i], 1e-3);
  }
}

TEST(Frf, ModesOfEq15AreTheDiagonalOscillators) {
  const Model& m = mdma();
  const Conditions c = make_conditions(m, 20.0);
  const State s = settle_at_bias(m, c, 1.0, BiasState::Anhysteretic);
  const auto modes = mechanical_modes(m, c, s);
  ASSERT_EQ(modes.size(), 3u);
  std::vector<double> fn;
  for (int i = 0; i < 3; ++i) {
    const auto& rc = c.rods[static_cast<std::size_t>(i)];
    const double K = oscillator_stiffness(c, s, i);
    fn.push_back(std::sqrt(K / rc.mass_osc_kg) / kTwoPi);
  }
  std::sort(fn.begin(), fn.end());
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(modes[k].frequency_Hz, fn[k], 1e-9 * fn[k]);
    EXPECT_GT(modes[k].damping_ratio, 0.0);
  }
  // READING-NOTES: the oscillators of eq. (15) ring at several kHz, above the 1270 Hz of
  // Fig. 15, which is the output stage's (3.52 / 4.26 / 5.94 kHz at this bias point for the
  // built-in model; 5.97 / 7.82 / 10.2 kHz with Table 5's E_s): the first resonance is not
  // a rod's.
  EXPECT_GT(modes[0].frequency_Hz, 2.5 * 1270.0);
  EXPECT_LT(modes[2].frequency_Hz, 15000.0);
}

// The stepped sine (time-domain runs of the full nonlinear step) and the linearisation
// agree in the linear regime. Two residuals remain (docs/experiments.md): the JA
// irreversible magnetisation, proportional to the amplitude (+0.004 % in |Y/I| at 20 uA,
// +0.018 % at 80 uA for the built-in model; 0.002 / 0.010 % for the printed reading), and an O(dt)
// phase lag of the time stepping (<= 0.08 deg here). Both readings: the printed one (eq. 7's lag of
// H behind H_c) and the consistent one (the rods' port equations with the eddy field kappa dB/dt,
// and the output stage).
void expect_stepped_sine_matches_linearisation(const Model& m) {
  FrfRequest r;
  r.temperatures_C = {20, 70};
  r.f_min_Hz = 5.0;
  r.f_max_Hz = 3000.0;
  r.points = 4;  // 5, 42, 357, 3000 Hz
  r.amplitude_A = 2e-5;
  const FrfResult small = run_frf(m, r);
  ASSERT_EQ(small.curves.size(), 2u);
  for (const auto& cv : small.curves) {
    EXPECT_LT(cv.max_mismatch_pct, 1.5) << cv.temperature_C << " degC";  // observed 0.15 %
    for (std::size_t k = 0; k < cv.f_Hz.size(); ++k)
      EXPECT_NEAR(cv.stepped_phase_deg[k], cv.linear_phase_deg[k], 0.8) << cv.f_Hz[k] << " Hz";
  }
  // Four times the amplitude: four times the magnitude excess at low frequency.
  r.temperatures_C = {20};
  r.amplitude_A = 8e-5;
  const FrfResult larger = run_frf(m, r);
  auto excess = [](const FrfCurve& c) {
    return c.stepped_mag_um_per_A[0] / c.linear_mag_um_per_A[0] - 1.0;
  };
  EXPECT_GT(excess(small.curves[0]), 0.0);
  EXPECT_NEAR(excess(larger.curves[0]) / excess(small.curves[0]), 4.0, 0.4);  // observed 4.00
}

TEST(Frf, SteppedSineMatchesTheLinearisationInTheLinearRegime) {
  expect_stepped_sine_matches_linearisation(mdma());
}

TEST(Frf, PrintedReadingSteppedSineMatchesTheLinearisation) {
  expect_stepped_sine_matches_linearisation(mdma_printed());
}

// The printed reading cannot carry Fig. 15: its eddy lag sets a bandwidth of a few hundred Hz
// and nothing rings below 5 kHz (READING-NOTES). The built-in model's sensor mount carries the
// measured 1270 Hz (fitted: the bracket's stiffness is a calibration parameter); being
// temperature-independent, the peak moves < 0.17 % from 20 to 70 degC (observed 0.005 %), as
// the paper measures. Its antiresonance just above the peak (the probe then moves in phase with
// the target) sets the -3 dB point (observed 1299 Hz against the paper's > 2000 Hz; docs/
// failing_claims.md), and the peak's amplitude follows the stack's small-signal gain, which
// falls with temperature (observed -41 %; the paper: hardly changes).
TEST(Frf, ResonanceAndBandwidthOfBothReadings) {
  FrfRequest r;
  r.temperatures_C = {20, 70};
  r.stepped_sine = false;
  r.points = 160;
  const FrfResult printed = run_frf(mdma_printed(), r);
  for (const auto& cv : printed.curves) {
    EXPECT_GT(cv.bandwidth_3dB_Hz, 100.0);
    EXPECT_LT(cv.bandwidth_3dB_Hz, 2000.0);
    EXPECT_EQ(cv.first_resonance_Hz, 0.0);
  }
  const FrfResult built_in = run_frf(mdma(), r);
  const auto& sm = mdma().sensor_mount;
  const double fn = std::sqrt(sm.stiffness_N_per_m / sm.mass_kg) / (2.0 * physics::kPi);
  for (const auto& cv : built_in.curves) {
    EXPECT_NEAR(cv.first_resonance_Hz, 1270.0, 0.01 * 1270.0) << cv.temperature_C;
    EXPECT_NEAR(cv.first_resonance_Hz, fn, 0.03 * fn) << cv.temperature_C;  // the mount's
    EXPECT_GT(cv.bandwidth_3dB_Hz, cv.first_resonance_Hz);                  // antiresonance
    EXPECT_LT(cv.bandwidth_3dB_Hz, 1.1 * cv.first_resonance_Hz);
    EXPECT_GT(cv.first_resonance_mag_um_per_A, cv.static_gain_um_per_A);
  }
  const auto& c0 = built_in.curves[0];
  const auto& c1 = built_in.curves[1];
  EXPECT_LT(std::fabs(c1.first_resonance_Hz / c0.first_resonance_Hz - 1.0), 0.0017);
  EXPECT_LT(c1.first_resonance_mag_um_per_A, c0.first_resonance_mag_um_per_A);
}

// Starting from the virgin curve instead, the JA minor loop creeps (M_irr keeps moving on
// every rising half-period) and the stepped sine does not measure the linear response.
TEST(Frf, VirginBiasStateCreepsAndDoesNotMatch) {
  FrfRequest r;
  r.temperatures_C = {20};
  r.f_min_Hz = 200.0;
  r.f_max_Hz = 400.0;
  r.points = 2;
  r.bias_state = BiasState::InitialCurve;
  const FrfResult res = run_frf(mdma(), r);
  EXPECT_GT(res.curves[0].max_mismatch_pct, 10.0);
}

TEST(Frf, BadRequestsAreClearInputErrors) {
  const Model& m = mdma();
  auto run = [&](auto edit) {
    return input_error_of([&] {
      FrfRequest r;
      r.points = 2;
      r.stepped_sine = false;
      edit(r);
      run_frf(m, r);
    });
  };
  EXPECT_NE(run([](FrfRequest& r) { r.f_min_Hz = 0; }).find("must be > 0"), std::string::npos);
  EXPECT_NE(run([](FrfRequest& r) { r.f_max_Hz = 0.5; }).find("must exceed"), std::string::npos);
  EXPECT_NE(run([](FrfRequest& r) { r.temperatures_C = {400}; }).find("Curie"), std::string::npos);
  EXPECT_NE(run([](FrfRequest& r) { r.temperatures_C.clear(); }).find("no temperature"),
            std::string::npos);
  EXPECT_NE(run([](FrfRequest& r) { r.amplitude_A = 0; }).find("amplitude"), std::string::npos);
  EXPECT_NE(run([](FrfRequest& r) { r.peak_refinements = -5; }).find("--peak-refinements"),
            std::string::npos);
  EXPECT_NE(run([](FrfRequest& r) { r.peak_refinements = 2000000000; }).find("--peak-refinements"),
            std::string::npos);
}

// The stepped-sine grid in SIMD lanes (frf_lanes.cpp) against one scalar run per point: the
// same grids, drive and first harmonic, bit for bit since the laws are written once (issue 38:
// gmasim/physics/laws-inl.h, ja_law-inl.h). Before, the lanes' rounding (~1e-12 of y) showed at
// ~1e-7 of the ~1e-5 response and grew over the long low-frequency runs: 7.8e-6 relative in |Y|
// and 3.0e-4 deg at most on this grid (tolerances 8e-5 and 3e-3 deg then; now 0).
TEST(Frf, SteppedSineInLanesMatchesTheScalarPoints) {
  FrfRequest r;
  r.temperatures_C = {20, 70};
  r.f_min_Hz = 5.0;
  r.f_max_Hz = 3000.0;
  r.points = 10;  // 10 points of 2 temperatures: 3 batches of 8 lanes on AVX-512
  r.peak_refinements = 0;
  const FrfResult lanes = run_frf(mdma(), r);
  r.lanes = false;
  const FrfResult scalar = run_frf(mdma(), r);
  ASSERT_EQ(lanes.curves.size(), scalar.curves.size());
  double worst_mag = 0.0, worst_deg = 0.0;
  for (std::size_t ti = 0; ti < lanes.curves.size(); ++ti) {
    const FrfCurve &a = lanes.curves[ti], &b = scalar.curves[ti];
    ASSERT_EQ(a.stepped_mag_um_per_A.size(), b.stepped_mag_um_per_A.size());
    for (std::size_t k = 0; k < a.stepped_mag_um_per_A.size(); ++k) {
      worst_mag = std::max(worst_mag,
                           std::fabs(a.stepped_mag_um_per_A[k] / b.stepped_mag_um_per_A[k] - 1.0));
      worst_deg = std::max(worst_deg, std::fabs(a.stepped_phase_deg[k] - b.stepped_phase_deg[k]));
    }
  }
  EXPECT_EQ(worst_mag, 0.0);
  EXPECT_EQ(worst_deg, 0.0);
  std::printf("lanes vs scalar: |Y| %.3g relative, phase %.3g deg\n", worst_mag, worst_deg);
}
