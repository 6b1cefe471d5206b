// The experiments of sections 4.4, 4.5 and 5 (src/experiments): numbers, not plumbing.
// Tolerances are about 10x the residual observed on this model (noted at each check).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "gmasim/compensate.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments.hpp"
#include "gmasim/io.hpp"
#include "gmasim/model.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/reproduce.hpp"
#include "gmasim/simulate.hpp"

using namespace gmasim;

namespace {

const Model& mdma() {
  static const Model m = load_model("");
  return m;
}

// The paper-as-printed reading (models/mdma_printed.toml): eq. 2, 3, 7, 10, 11 as printed.
const Model& mdma_printed() {
  static const Model m = load_model(std::string(GMASIM_SOURCE_DIR) + "/models/mdma_printed.toml");
  return m;
}

constexpr double kTwoPi = 2.0 * physics::kPi;

template <class F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Sweep
// ---------------------------------------------------------------------------------------
TEST(Sweep, PointsAreTheSimulateMetricsAndChangesAreAgainstTheReference) {
  const Model& m = mdma();
  SweepRequest r;
  r.temperatures_C = {30, 70};  // the reference (20 degC) is not a grid point: run, not listed
  r.currents_pp_A = {6};
  r.frequencies_Hz = {10, 50};
  r.periods = 2;
  const SweepResult res = run_sweep(m, r);
  ASSERT_EQ(res.points.size(), 4u);
  ASSERT_EQ(res.reference_points.size(), 2u);
  EXPECT_EQ(res.simulations, 6);
  // Order: temperature-major, then current, then frequency.
  EXPECT_EQ(res.points[1].temperature_C, 30);
  EXPECT_EQ(res.points[1].frequency_Hz, 50);
  EXPECT_EQ(res.points[2].temperature_C, 70);
  // A point is exactly simulate() at its settings.
  SimulationSettings s;
  s.temperature_C = 70;
  s.waveform = biased_sine(6, 50);
  s.periods = 2;
  const Result direct = simulate(m, s);
  EXPECT_EQ(res.points[3].metrics.stroke_um, direct.metrics.stroke_um);
  EXPECT_EQ(res.points[3].metrics.hysteresis_um, direct.metrics.hysteresis_um);
  EXPECT_EQ(res.points[3].metrics.B_pp_T, direct.metrics.B_pp_T);
  // Relative change against the 20 degC run at equal current and frequency.
  const auto& ref = res.reference_points[1];
  EXPECT_EQ(ref.temperature_C, 20);
  EXPECT_NEAR(res.points[3].stroke_change_pct,
              (direct.metrics.stroke_um - ref.metrics.stroke_um) / ref.metrics.stroke_um * 100,
              1e-12);
  EXPECT_NEAR(
      res.points[3].hysteresis_change_pct,
      (direct.metrics.hysteresis_um - ref.metrics.hysteresis_um) / ref.metrics.hysteresis_um * 100,
      1e-12);
  // The paper's trend (section 4.4.4): stroke and hysteresis fall from 20 to 70 degC.
  EXPECT_LT(res.points[2].stroke_change_pct, 0.0);
  EXPECT_LT(res.points[2].hysteresis_change_pct, 0.0);
}

TEST(Sweep, DeterministicWhateverTheThreadCount) {
  const Model& m = mdma();
  SweepRequest r;
  r.temperatures_C = {20, 45, 70};
  r.currents_pp_A = {6, 10};
  r.frequencies_Hz = {20};
  r.periods = 2;
  r.threads = 1;
  const SweepResult a = run_sweep(m, r);
  r.threads = 3;
  std::size_t calls = 0, last = 0;
  bool increasing = true;
  const SweepResult b = run_sweep(m, r, [&](std::size_t done, std::size_t total) {
    // serialised by the sweep: no lock needed here
    ++calls;
    increasing = increasing && done == last + 1 && total == 6;
    last = done;
  });
  EXPECT_EQ(b.threads, 3);
  EXPECT_EQ(calls, 6u);
  EXPECT_TRUE(increasing);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i].temperature_C, b.points[i].temperature_C);
    EXPECT_EQ(a.points[i].metrics.stroke_um, b.points[i].metrics.stroke_um);  // bitwise
    EXPECT_EQ(a.points[i].metrics.hysteresis_um, b.points[i].metrics.hysteresis_um);
    EXPECT_EQ(a.points[i].metrics.B_pp_T, b.points[i].metrics.B_pp_T);
    EXPECT_EQ(a.points[i].stroke_change_pct, b.points[i].stroke_change_pct);
  }
}

TEST(Sweep, ADivergedPointIsRecordedAndTheSweepContinues) {
  SweepRequest r;
  r.temperatures_C = {20};
  // A coil of 7.2e6 turns: 6 mA peak-to-peak drive it as 60 A would the MDMA's; 1000 A
  // (kMaxCurrent_A) takes the field out of the physical range.
  ModelSpec spec = builtin_model_spec();
  spec.set("circuit.branches.phi4.coil_turns", 7.2e6);
  r.current_min_A = -3e-3;
  r.currents_pp_A = {6e-3, 1000.0};
  r.frequencies_Hz = {50};
  r.periods = 1;
  const SweepResult res = run_sweep(compile(spec), r);
  ASSERT_EQ(res.points.size(), 2u);
  EXPECT_FALSE(res.points[0].diverged);
  EXPECT_GT(res.points[0].metrics.stroke_um, 1.0);
  EXPECT_TRUE(res.points[1].diverged);
  EXPECT_NE(res.points[1].error.find("diverged"), std::string::npos) << res.points[1].error;
}

TEST(Sweep, BadRequestsAreClearInputErrors) {
  const Model& m = mdma();
  auto run = [&](auto edit) {
    return input_error_of([&] {
      SweepRequest r;
      r.periods = 1;
      edit(r);
      run_sweep(m, r);
    });
  };
  EXPECT_NE(run([](SweepRequest& r) { r.temperatures_C.clear(); }).find("empty grid"),
            std::string::npos);
  EXPECT_NE(run([](SweepRequest& r) { r.currents_pp_A.clear(); }).find("empty grid"),
            std::string::npos);
  EXPECT_NE(run([](SweepRequest& r) { r.frequencies_Hz.clear(); }).find("empty grid"),
            std::string::npos);
  EXPECT_NE(run([](SweepRequest& r) {
              r.frequencies_Hz = {10, 0};
            }).find("frequency 0 Hz: must be > 0"),
            std::string::npos);
  EXPECT_NE(run([](SweepRequest& r) { r.frequencies_Hz = {-5}; }).find("must be > 0"),
            std::string::npos);
  EXPECT_NE(run([](SweepRequest& r) {
              r.temperatures_C = {20, 400};
            }).find("Curie"),
            std::string::npos);
  EXPECT_NE(run([](SweepRequest& r) { r.temperatures_C = {500}; }).find("Curie"),
            std::string::npos);
  EXPECT_NE(run([](SweepRequest& r) { r.reference_temperature_C = 400; }).find("Curie"),
            std::string::npos);
}

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
// +0.018 % at 80 uA for the built-in model; 0.002 / 0.010 % for the printed reading), and an O(dt) phase lag of the time stepping (<= 0.08 deg here).
// Both readings: the printed one (eq. 7's lag of H behind H_c) and the consistent one (the
// rods' port equations with the eddy field kappa dB/dt, and the output stage).
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

// The printed reading cannot carry Fig. 15: its eddy lag sets a bandwidth of a few hundred
// Hz and nothing rings below 5 kHz (READING-NOTES). The built-in model's output stage
// carries the measured 1270 Hz with the bandwidth above 2000 Hz. Its peak shifts 1.4 %
// from 20 to 70 degC (paper < 0.17 %): with damping ratio 0.37 the peak is shaped by the
// eddy lag, whose time constant falls as rho rises (eq. 8). A lightly damped stage (ratio
// 0.09) keeps the shift < 0.2 %, so the mechanics alone are temperature-independent, but it
// loses the bandwidth (the -3 dB point of a lightly damped mode lies at ~1.5 f_n) and
// destabilises the PID of Fig. 16 (docs/calibration.md).
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
  auto shift_of = [](const FrfResult& res) {
    return std::fabs(res.curves[1].first_resonance_Hz / res.curves[0].first_resonance_Hz - 1.0);
  };
  const FrfResult built_in = run_frf(mdma(), r);
  EXPECT_NEAR(built_in.curves[0].first_resonance_Hz, 1270.0, 0.01 * 1270.0);      // 1272 Hz
  for (const auto& cv : built_in.curves) EXPECT_GT(cv.bandwidth_3dB_Hz, 2000.0);  // 2054, 2135
  EXPECT_GT(shift_of(built_in), 0.01);                                            // observed 1.4 %
  EXPECT_LT(shift_of(built_in), 0.03);

  ModelSpec light = builtin_model_spec();
  light.set("mechanics.output_stage.damping_N_s_per_m", 10.0);
  light.set("mechanics.output_stage.stiffness_N_per_m", 4.6e5);
  const FrfResult lightly_damped = run_frf(compile(light), r);
  for (const auto& cv : lightly_damped.curves) {
    EXPECT_NEAR(cv.first_resonance_Hz, 1270.0, 0.02 * 1270.0) << cv.temperature_C << " degC";
    EXPECT_LT(cv.bandwidth_3dB_Hz, 1.6 * cv.first_resonance_Hz);  // observed 1.48
  }
  EXPECT_LT(shift_of(lightly_damped), 0.002);  // observed 0.08 %; the paper: < 0.17 %
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
}

// ---------------------------------------------------------------------------------------
// PID and closed-loop tracking
// ---------------------------------------------------------------------------------------
namespace {

// First-order linear plant tau dy/dt = K u - y, exact zero-order-hold discretisation.
struct FirstOrderPlant {
  double K, tau, Ts, y = 0.0;
  double step(double u) {
    const double a = std::exp(-Ts / tau);
    y = a * y + (1 - a) * K * u;
    return y;
  }
};

}  // namespace

TEST(Pid, SteadyStateErrorVanishesOnALinearPlant) {
  const double fs = 10000.0;
  // A plant like the actuator's large-signal slope: 7 um/A, 0.5 ms lag.
  FirstOrderPlant plant{7.0, 5e-4, 1.0 / fs};
  Pid pid(PidGains{}, fs, -100.0, 100.0);
  const double ref = 10.0;  // um
  double e = ref;
  for (int k = 0; k < 4000; ++k) {
    e = ref - plant.y;
    plant.step(pid.update(e));
  }
  EXPECT_LT(std::fabs(ref - plant.y), 1e-9);
  EXPECT_NEAR(pid.integral_sum() * 0.03, ref / 7.0, 1e-9);  // the integrator holds u = r/K
  // P only: the analytic steady-state error r / (1 + kp K).
  FirstOrderPlant p2{7.0, 5e-4, 1.0 / fs};
  Pid ponly(PidGains{0.2, 0.0, 0.0, fs}, fs, -100.0, 100.0);
  for (int k = 0; k < 4000; ++k) p2.step(ponly.update(ref - p2.y));
  EXPECT_NEAR(ref - p2.y, ref / (1.0 + 0.2 * 7.0), 1e-9);
}

TEST(Pid, GainsDescribeTheSameControllerAtAnySampleRate) {
  // ki, kd are per-sample at the gains' reference rate (10 kHz): at 20 kHz the same
  // constant error for the same time integrates to the same output.
  Pid a(PidGains{0.0, 0.03, 0.0, 10000.0}, 10000.0, -1e9, 1e9);
  Pid b(PidGains{0.0, 0.03, 0.0, 10000.0}, 20000.0, -1e9, 1e9);
  double ua = 0, ub = 0;
  for (int k = 0; k < 10000; ++k) ua = a.update(1.0);  // 1 s
  for (int k = 0; k < 20000; ++k) ub = b.update(1.0);  // 1 s
  EXPECT_NEAR(ua, 300.0, 1e-9);                        // ki * rate * t * e
  EXPECT_NEAR(ub, 300.0, 1e-9);
  // Derivative: a ramp e = t [um/s] gives kd * rate_ref * de/dt at both rates.
  Pid da(PidGains{0.0, 0.0, 0.007, 10000.0}, 10000.0, -1e9, 1e9);
  Pid db(PidGains{0.0, 0.0, 0.007, 10000.0}, 20000.0, -1e9, 1e9);
  da.update(0.0);
  db.update(0.0);
  EXPECT_NEAR(da.update(1e-4), 0.007 / 10000.0 * 1.0, 1e-15);  // Kd = kd / rate_ref [A s/um]
  EXPECT_NEAR(db.update(5e-5), 0.007 / 10000.0 * 1.0, 1e-15);
}

TEST(Pid, OutputIsClippedWithoutWindUp) {
  Pid pid(PidGains{0.2, 0.03, 0.0, 10000.0}, 10000.0, -2.0, 2.0);
  for (int k = 0; k < 1000; ++k) EXPECT_LE(pid.update(50.0), 2.0);
  const double held = pid.integral_sum();
  EXPECT_LT(held * 0.03, 3.0);  // the sum stopped growing once the output clipped
  // A reversed error leaves saturation at once instead of unwinding a huge sum.
  EXPECT_LT(pid.update(-20.0), 2.0);
}

TEST(Track, ClosedLoopTracksAndIsDeterministic) {
  const Model& m = mdma();
  TrackRequest r;
  r.temperatures_C = {20, 70};
  r.amplitudes_um = {10};
  r.frequencies_Hz = {10};
  r.periods = 2;
  r.threads = 1;
  const TrackResult a = run_track(m, r);
  ASSERT_EQ(a.points.size(), 2u);
  for (const auto& p : a.points) {
    EXPECT_FALSE(p.diverged) << p.error;
    EXPECT_FALSE(p.saturated);
    EXPECT_LT(p.error_rms_um, 0.5);  // observed 0.19 / 0.20 um: 2 % of the amplitude
    EXPECT_GT(p.error_rms_um, 0.01);
    EXPECT_GE(p.error_peak_um, p.error_rms_um);
  }
  EXPECT_EQ(a.points[0].error_change_pct, 0.0);
  EXPECT_GT(a.points[1].error_change_pct, 0.0);  // hotter: less stroke per ampere, more error
  // The example series is the first point, sampled at the controller rate.
  EXPECT_EQ(a.example.names[1], "reference_um");
  EXPECT_EQ(a.example.rows(), static_cast<std::size_t>(std::lround(2 * 0.1 * r.sample_rate_Hz)));
  r.threads = 2;
  const TrackResult b = run_track(m, r);
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i].error_rms_um, b.points[i].error_rms_um);
    EXPECT_EQ(a.points[i].error_peak_um, b.points[i].error_peak_um);
  }
  // Sensor noise from a seeded generator: reproducible, and it adds error.
  r.sensor_noise_um = 1.0;
  const TrackResult n1 = run_track(m, r), n2 = run_track(m, r);
  EXPECT_EQ(n1.points[0].error_rms_um, n2.points[0].error_rms_um);
  EXPECT_GT(n1.points[0].error_rms_um, a.points[0].error_rms_um);
}

// Why the gains are per sample at 10 kHz (docs/experiments.md): read as continuous gains
// with time in seconds (ki 0.03 A/(um s), kd 0.007 A s/um) the loop is unstable.
TEST(Track, ContinuousSecondsReadingOfTheGainsIsUnstable) {
  TrackRequest r;
  r.temperatures_C = {20};
  r.amplitudes_um = {10};
  r.frequencies_Hz = {10};
  r.periods = 1;
  r.gains = PidGains{0.2, 0.03 / 10000.0, 0.007 * 10000.0, 10000.0};
  const TrackResult res = run_track(mdma(), r);
  EXPECT_TRUE(res.points[0].saturated);
  EXPECT_GT(res.points[0].error_rms_um, r.amplitudes_um[0]);
}

TEST(Track, BadRequestsAreClearInputErrors) {
  const Model& m = mdma();
  auto run = [&](auto edit) {
    return input_error_of([&] {
      TrackRequest r;
      r.temperatures_C = {20};
      r.periods = 1;
      edit(r);
      run_track(m, r);
    });
  };
  EXPECT_NE(run([](TrackRequest& r) {
              r.sample_rate_Hz = 150;
              r.frequencies_Hz = {10, 100};
            }).find("below twice the reference frequency 100 Hz"),
            std::string::npos);
  EXPECT_NE(run([](TrackRequest& r) { r.frequencies_Hz = {0}; }).find("must be > 0"),
            std::string::npos);
  EXPECT_NE(run([](TrackRequest& r) { r.temperatures_C = {400}; }).find("Curie"),
            std::string::npos);
  EXPECT_NE(run([](TrackRequest& r) { r.bias_A = 20; }).find("inside the current limit"),
            std::string::npos);
}

// ---------------------------------------------------------------------------------------
// Ablation
// ---------------------------------------------------------------------------------------
TEST(Ablate, FrozenLawsChangeNothingAtTheReferenceTemperature) {
  AblateRequest r;
  r.temperature_C = mdma().T_ref_C;
  r.frequencies_Hz = {50};
  r.periods = 1;
  const AblateResult res = run_ablate(mdma(), r);
  ASSERT_EQ(res.rows.size(), ablation_laws().size());
  for (const auto& row : res.rows) EXPECT_EQ(row.error_rms_um, 0.0) << row.law;
}

TEST(Ablate, MagnetisationMattersMostAtLowFrequencyAndResistivityGrowsWithFrequency) {
  AblateRequest r;  // 70 degC, 6 A, 10 and 200 Hz (Fig. 20)
  r.periods = 2;
  const AblateResult res = run_ablate(mdma(), r);
  auto err = [&](const std::string& law, double f) {
    for (const auto& row : res.rows)
      if (row.law == law && row.frequency_Hz == f) return row.error_rms_um;
    ADD_FAILURE() << law;
    return 0.0;
  };
  // Section 5: M first, then E_G and mu_G (observed M 2.93, E_G 0.69, mu_G 0.79 um at 10 Hz: E_G
  // and mu_G swap, a failing claim, docs/failing_claims.md).
  for (const char* law : {"mu_G", "rho_G", "E_G", "E_t", "F_pm", "geometry"})
    EXPECT_GT(err("M", 10), err(law, 10)) << law;
  EXPECT_GT(err("E_G", 10), err("rho_G", 10));
  EXPECT_GT(err("mu_G", 10), err("rho_G", 10));
  // Eddy currents: rho_G matters far more at 200 Hz (observed 0.045 -> 0.67 um).
  EXPECT_GT(err("rho_G", 200), 5.0 * err("rho_G", 10));
  // The PM drift (eq. 1; section 4.4.1 ignores it): freezing it changes nothing when the
  // model's alpha_pm1 is 0 (the built-in model's identified value), and little otherwise.
  // E_t acts through the sleeves in series with the soft disk spring: negligible.
  const Model& m = mdma();
  if (m.alpha_pm1_per_K == 0.0 && m.alpha_pm2_per_K2 == 0.0)
    EXPECT_EQ(err("F_pm", 10), 0.0);
  else
    EXPECT_GT(err("F_pm", 10), 0.0);
  EXPECT_LT(err("F_pm", 10), 0.2 * err("M", 10));
  EXPECT_LT(err("E_t", 10), 1e-3 * err("mu_G", 10));
  // Freezing every law restores the 20 degC output: the error is of the order of M's
  // (observed 2.73 vs 2.93 um: the laws partly cancel).
  EXPECT_GT(err("all", 10), 0.5 * err("M", 10));
}

// ---------------------------------------------------------------------------------------
// Parameters against temperature, retention, thermal expansion
// ---------------------------------------------------------------------------------------
TEST(ParamsVsTemperature, LawsAndRetention) {
  const Model& m = mdma();
  ParamsVsTemperatureRequest r;
  r.temperatures_C = {20, 150};
  r.retention_currents_pp_A = {6};  // the 8 A point of Fig. 19 is run as well
  r.periods = 2;
  const auto res = run_params_vs_temperature(m, r);
  ASSERT_EQ(res.rows.size(), 2u * m.rods.size());
  const auto& hot = res.rows[m.rods.size()];  // rod 1 at 150 degC
  EXPECT_EQ(hot.temperature_C, 150);
  // Eq. (8), eq. (19), eq. (4) evaluated directly.
  EXPECT_NEAR(hot.rho_ohm_m, m.material.rho0_ohm_m + m.material.drho_dT_ohm_m_per_K * 130.0, 1e-18);
  EXPECT_NEAR(hot.E_t_GPa, (m.Et_Pa - m.dEt_dT_Pa_per_C * 150.0) * 1e-9, 1e-9);
  EXPECT_NEAR(hot.MsT_A_per_m,
              physics::saturation_magnetisation(m.material.Ms_A_per_m, 130.0,
                                                m.material.Tc_C - m.T_ref_C, m.material.x_exponent),
              1e-6);
  EXPECT_NEAR(hot.rho_change_pct, 130.0 * 2.5e-9 / 6e-7 * 100.0, 1e-9);
  EXPECT_EQ(res.rows[0].E_G_change_pct, 0.0);
  EXPECT_GT(hot.mu_r_mean, 1.0);
  EXPECT_GT(hot.E_G_mean_GPa, 10.0);
  ASSERT_EQ(res.retention.size(), 2u);
  EXPECT_EQ(res.retention[0].stroke_retention_pct, 100.0);
  // Fig. 18: the output at 150 degC is ~70 % of that at 20 degC (observed 65.8 % at 6 A).
  EXPECT_GT(res.retention[1].stroke_retention_pct, 50.0);
  EXPECT_LT(res.retention[1].stroke_retention_pct, 90.0);
}

TEST(Thermal, Eq21FromTheComponentLengths) {
  const Model& m = mdma();
  const auto t = thermal_expansion_coefficient(m);
  const auto& p = m.spec;
  const double expect =
      (p.get("thermal_expansion.rod_length_m") * p.get("material.alpha_thermal_per_K") +
       p.get("thermal_expansion.magnetizer_length_m") *
           p.get("thermal_expansion.magnetizer_alpha_per_K") +
       p.get("thermal_expansion.output_rod_length_m") *
           p.get("thermal_expansion.output_rod_alpha_per_K") -
       p.get("thermal_expansion.sleeve_length_m") * p.get("thermal_expansion.sleeve_alpha_per_K")) *
      1e6;
  EXPECT_NEAR(t.um_per_C, expect, 1e-12);
  EXPECT_NEAR(t.um_per_C, 0.662, 1e-3);  // the sleeve length was chosen for the paper's value
  EXPECT_NEAR(t.rod_um_per_C + t.magnetizer_um_per_C + t.output_rod_um_per_C - t.sleeve_um_per_C,
              t.um_per_C, 1e-12);
  // Eq. (21) is what make_conditions puts in x_T.
  EXPECT_NEAR(make_conditions(m, 70.0).thermal_expansion_m * 1e6, 50.0 * t.um_per_C, 1e-9);
}

// ---------------------------------------------------------------------------------------
// Reports
// ---------------------------------------------------------------------------------------
TEST(Report, CsvAndJsonCarryTheSameRows) {
  Table t{"points", {"temperature_C", "stroke_um", "status"}, {}};
  t.rows.push_back({20.0, 44.797948905156, "ok"});
  t.rows.push_back({70.0, std::nan(""), "diverged, at t = 1 s"});
  const std::string csv = table_csv(t);
  EXPECT_EQ(csv,
            "temperature_C,stroke_um,status\n20,44.797948905156,ok\n70,,\"diverged, at t = 1 "
            "s\"\n");  // a missing value is an empty cell
  Report r{"sweep", {{"threads", 2}, {"ok", true}}, {t}};
  const std::string json = report_json(r);
  EXPECT_NE(json.find("\"stroke_um\": 44.797948905156"), std::string::npos) << json;
  EXPECT_NE(json.find("\"stroke_um\": null"), std::string::npos);  // NaN is null in JSON
  EXPECT_NE(json.find("\"ok\": true"), std::string::npos);
}

// ---------------------------------------------------------------------------------------
// CLI: exit codes of bad requests (the gmasim binary next to this test binary)
// ---------------------------------------------------------------------------------------
namespace {

std::string gmasim_binary() {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const auto bin = self.parent_path() / "gmasim";
  return std::filesystem::exists(bin) ? bin.string() : std::string();
}

int run_cli(const std::string& args, std::string& output) {
  const std::string bin = gmasim_binary();
  const auto out = std::filesystem::temp_directory_path() /
                   ("gmasim_exp_cli_" + std::to_string(::getpid()) + ".txt");
  const int rc = std::system((bin + " " + args + " >" + out.string() + " 2>&1").c_str());
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  output = ss.str();
  std::filesystem::remove(out);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

}  // namespace

TEST(ExperimentsCli, BadRequestsExitWithCode2AndSayWhy) {
  if (gmasim_binary().empty()) GTEST_SKIP() << "gmasim binary not built";
  const auto dir =
      std::filesystem::temp_directory_path() / ("gmasim_exp_" + std::to_string(::getpid()));
  const std::string out = " --out " + dir.string();
  std::string text;
  EXPECT_EQ(run_cli("sweep --frequencies 0" + out, text), 2);
  EXPECT_NE(text.find("frequency 0 Hz: must be > 0"), std::string::npos) << text;
  EXPECT_EQ(run_cli("sweep --temperatures ''" + out, text), 2);
  EXPECT_NE(text.find("empty grid"), std::string::npos) << text;
  EXPECT_EQ(run_cli("sweep --temperatures 20,abc" + out, text), 2);
  EXPECT_NE(text.find("'abc' is not a finite number [degC]"), std::string::npos) << text;
  EXPECT_EQ(run_cli("frf --temperatures 400" + out, text), 2);
  EXPECT_NE(text.find("Curie"), std::string::npos) << text;
  EXPECT_EQ(run_cli("track --sample-rate 150 --frequencies 100" + out, text), 2);
  EXPECT_NE(text.find("below twice the reference frequency"), std::string::npos) << text;
  EXPECT_EQ(run_cli("ablate --temperature 400" + out, text), 2);
  // A small sweep writes CSV and JSON and lists the points.
  EXPECT_EQ(
      run_cli("sweep --temperatures 20,70 --currents 6 --frequencies 50 --periods 1" + out, text),
      0)
      << text;
  EXPECT_TRUE(std::filesystem::exists(dir / "sweep.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "sweep.json"));
  std::ifstream csv(dir / "sweep.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(
      header.rfind("temperature_C,current_pp_A,frequency_Hz,stroke_um,hysteresis_um,B_pp_T", 0),
      0u);
  std::filesystem::remove_all(dir);
}

// docs/reproduction.md explains every failing claim (issue 7, item 4): the notes file's
// "### <id>" sections reach the page under their claim; failures without one are named.
TEST(ReproductionDoc, FailingClaimsCarryTheirExplanations) {
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("gmasim_notes_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path notes_path = dir / "notes.md";
  std::ofstream(notes_path) << "# Why\n\nintro text, ignored\n\n### b_fails\n\nBecause eq. 8 "
                               "rises.\nSecond line.\n\n### a_passes\n\nnot shown\n";
  const auto notes = gmasim::load_claim_notes(notes_path.string());
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_EQ(notes[0].first, "b_fails");
  EXPECT_EQ(notes[0].second, "Because eq. 8 rises.\nSecond line.");

  gmasim::ReproduceResult r;
  auto claim = [](const char* id, bool pass, bool applicable) {
    gmasim::Claim c;
    c.id = id;
    c.claim = std::string("claim ") + id;
    c.pass = pass;
    c.applicable = applicable;
    return c;
  };
  r.claims = {claim("a_passes", true, true), claim("b_fails", false, true),
              claim("c_fails", false, true), claim("d_na", false, false)};
  EXPECT_EQ(gmasim::unexplained_failures(r.claims, notes), std::vector<std::string>{"c_fails"});

  const fs::path doc = dir / "reproduction.md";
  gmasim::write_reproduction_doc(r, {}, doc.string(), (dir / "no_out").string(), notes);
  std::stringstream ss;
  ss << std::ifstream(doc).rdbuf();
  const std::string md = ss.str();
  const auto why = md.find("## Why the failing claims fail");
  ASSERT_NE(why, std::string::npos);
  EXPECT_NE(md.find("### b_fails (claim b_fails)\n\nBecause eq. 8 rises.\nSecond line.", why),
            std::string::npos);
  EXPECT_NE(md.find("### c_fails (claim c_fails)\n\n*No explanation recorded.*", why),
            std::string::npos);
  EXPECT_EQ(md.find("### a_passes", why), std::string::npos);  // passing: not explained
  EXPECT_EQ(md.find("### d_na", why), std::string::npos);      // not applicable: not a failure

  // A heading without an id, or an id twice, is an error naming file:line.
  std::ofstream(notes_path) << "### x\n\ntext\n\n### x\n";
  try {
    (void)gmasim::load_claim_notes(notes_path.string());
    ADD_FAILURE() << "duplicate id accepted";
  } catch (const gmasim::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("notes.md:5: claim 'x' is explained twice"),
              std::string::npos)
        << e.what();
  }
  std::ofstream(notes_path) << "### \n";
  EXPECT_THROW((void)gmasim::load_claim_notes(notes_path.string()), gmasim::InputError);
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------
// Temperature compensation (issue 9, item 2)
// ---------------------------------------------------------------------------------------
TEST(Compensate, SolvedDriveRestoresTheTargetStrokeInEveryMode) {
  const gmasim::Model m = gmasim::load_model("");
  for (auto adjust : {gmasim::CompensationAdjust::Amplitude, gmasim::CompensationAdjust::Swing,
                      gmasim::CompensationAdjust::Scale}) {
    gmasim::CompensateRequest r;
    r.temperatures_C = {20.0, 90.0};
    r.adjust = adjust;
    r.periods = 2.0;
    r.tolerance_um = 1e-3;
    const auto res = gmasim::run_compensate(m, r);
    ASSERT_EQ(res.points.size(), 2u);
    EXPECT_NEAR(res.points[0].gain, 1.0, 1e-9);  // the reference temperature needs no change
    const auto& hot = res.points[1];
    ASSERT_TRUE(hot.reachable && !hot.diverged) << hot.error;
    EXPECT_NEAR(hot.stroke_um, res.target_stroke_um, r.tolerance_um);
    EXPECT_LT(hot.uncompensated_stroke_um, res.target_stroke_um - 1.0);  // it was lost
    EXPECT_GT(hot.gain, 1.05);
    // The drive, rerun independently, gives that stroke.
    gmasim::SimulationSettings s;
    s.temperature_C = 90.0;
    s.waveform = gmasim::biased_sine(hot.current_pp_A, r.frequency_Hz, hot.current_min_A);
    s.periods = r.periods;
    EXPECT_NEAR(gmasim::simulate(m, s).metrics.stroke_um, hot.stroke_um, 1e-9);
    EXPECT_LT(hot.evaluations, 30);
  }
}

TEST(Compensate, UnreachableTargetsAndBadRequestsAreReported) {
  const gmasim::Model m = gmasim::load_model("");
  gmasim::CompensateRequest r;
  r.temperatures_C = {150.0};
  r.max_current_A = 6.0;  // the reference 5 A peak fits, the hot drive does not
  r.periods = 2.0;
  const auto res = gmasim::run_compensate(m, r);
  EXPECT_FALSE(res.points[0].reachable);
  EXPECT_NEAR(res.points[0].current_max_A, 6.0, 1e-12);
  EXPECT_LT(res.points[0].stroke_um, res.target_stroke_um);
  auto refused = [&](auto edit, const char* what) {
    gmasim::CompensateRequest q;
    q.temperatures_C = {20.0};
    edit(q);
    EXPECT_THROW(
        {
          try {
            (void)gmasim::run_compensate(m, q);
          } catch (const gmasim::InputError& e) {
            EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr(what));
            throw;
          }
        },
        gmasim::InputError);
  };
  refused([](auto& q) { q.temperatures_C = {20.0, std::nan("")}; }, "temperature");
  refused([](auto& q) { q.temperatures_C = {400.0}; }, "Curie");
  refused([](auto& q) { q.temperatures_C = {70.0, 20.0}; }, "must increase");
  refused([](auto& q) { q.max_current_A = 4.0; }, "beyond the maximum current");
  refused([](auto& q) { q.max_current_A = 2.0; }, "current minimum = -3 A: must be in");
  refused([](auto& q) { q.reference_current_pp_A = 0.0; }, "must be > 0");
  refused([](auto& q) { q.target_stroke_um = 1e300; }, "target stroke");
  refused([](auto& q) { q.tolerance_um = 0.0; }, "stroke tolerance");
}

TEST(Compensate, UnitFeedforwardIsThePlainPid) {
  // g = 1 everywhere and no reference feed-forward: the same loop, to the last bit, as long
  // as the current does not clip.
  const gmasim::Model m = gmasim::load_model("");
  gmasim::TrackRequest t;
  t.temperatures_C = {20.0, 70.0};
  t.amplitudes_um = {10.0};
  t.frequencies_Hz = {10.0};
  t.periods = 2.0;
  const auto plain = gmasim::run_track(m, t);
  t.feedforward.temperatures_C = {20.0, 70.0};
  t.feedforward.gains = {1.0, 1.0};
  const auto unit = gmasim::run_track(m, t);
  for (std::size_t i = 0; i < plain.points.size(); ++i) {
    ASSERT_FALSE(plain.points[i].saturated);
    EXPECT_EQ(plain.points[i].error_rms_um, unit.points[i].error_rms_um);
  }
  EXPECT_DOUBLE_EQ(t.feedforward.gain_at(45.0), 1.0);
  t.feedforward.gains = {1.0, 2.0};
  EXPECT_DOUBLE_EQ(t.feedforward.gain_at(45.0), 1.5);
  EXPECT_DOUBLE_EQ(t.feedforward.gain_at(-10.0), 1.0);  // held beyond the ends
  EXPECT_DOUBLE_EQ(t.feedforward.gain_at(900.0), 2.0);
  t.feedforward.gains = {1.0};
  EXPECT_THROW((void)gmasim::run_track(m, t), gmasim::InputError);
}

TEST(StepMetrics, FirstOrderLagHasItsAnalyticRiseAndSettlingTimes) {
  // y = 1 - exp(-(t - t0)/tau) after t0: rise 10-90 % = tau ln 9, settling 2 % = tau ln 50.
  gmasim::TimeSeries ts;
  ts.names = {"t_s", "y_um"};
  ts.columns.assign(2, {});
  const double tau = 1e-3, t0 = 2e-3, dt = 1e-6;
  for (int k = 0; k <= 20000; ++k) {
    const double t = k * dt;
    ts.columns[0].push_back(t);
    ts.columns[1].push_back(t <= t0 ? 0.0 : 5.0 * (1.0 - std::exp(-(t - t0) / tau)));
  }
  const auto s = gmasim::step_metrics(ts, t0);
  ASSERT_TRUE(s.valid);
  EXPECT_NEAR(s.y_final_um, 5.0, 5.0 * 2e-6);
  EXPECT_NEAR(s.rise_time_s, tau * std::log(9.0), 2 * dt);
  EXPECT_NEAR(s.settling_time_s, tau * std::log(50.0), 2 * dt);
  EXPECT_NEAR(s.overshoot_pct, 0.0, 1e-3);
}
