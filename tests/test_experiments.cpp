// The experiments of sections 4.4, 4.5 and 5 (src/experiments): numbers, not plumbing.
// Tolerances are about 10x the residual observed on this model (noted at each check).
// The sweep, the ablation, the laws against temperature, the report tables and the step
// metrics here; the FRF in test_frf.cpp, PID, tracking and compensation in test_track.cpp,
// the CLI's refusals and the reproduction page in test_experiments_cli.cpp.
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

#include "experiments_fixtures.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/compensate.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/reproduce.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/simulate/simulate.hpp"

using namespace gmasim;
using namespace gmasim_experiments_test;

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
  // A point is exactly simulate_lanes() at its settings (its SIMD lane does not depend on the
  // other lanes), and simulate() to the lanes' rounding (docs/lanes.md; observed 1e-13
  // relative, tolerance 1e-11).
  SimulationSettings s;
  s.temperature_C = 70;
  s.waveform = biased_sine(6, 50);
  s.periods = 2;
  const Result direct = simulate_lanes(m, std::vector<SimulationSettings>{s}).at(0);
  EXPECT_EQ(res.points[3].metrics.stroke_um, direct.metrics.stroke_um);
  EXPECT_EQ(res.points[3].metrics.hysteresis_um, direct.metrics.hysteresis_um);
  EXPECT_EQ(res.points[3].metrics.B_pp_T, direct.metrics.B_pp_T);
  const Result scalar = simulate(m, s);
  EXPECT_NEAR(direct.metrics.stroke_um, scalar.metrics.stroke_um, 1e-11 * scalar.metrics.stroke_um);
  EXPECT_NEAR(direct.metrics.hysteresis_um, scalar.metrics.hysteresis_um,
              1e-11 * scalar.metrics.stroke_um);
  EXPECT_NEAR(direct.metrics.B_pp_T, scalar.metrics.B_pp_T, 1e-11 * scalar.metrics.B_pp_T);
  std::printf("sweep point vs simulate(): stroke %.3g, B_pp %.3g relative\n",
              std::fabs(direct.metrics.stroke_um / scalar.metrics.stroke_um - 1),
              std::fabs(direct.metrics.B_pp_T / scalar.metrics.B_pp_T - 1));
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

// Without lanes a sweep point records only the metrics' window (simulate_metrics_only), not the
// series: its metrics are simulate()'s at its settings, bit for bit; so is a diverged point's
// error.
TEST(Sweep, ScalarPointsAreSimulateBitForBit) {
  SweepRequest r;
  r.temperatures_C = {20, 70};
  // The coil of the test above: 1000 A diverges, 6 mA is the MDMA's 6 A.
  r.current_min_A = -3e-3;
  r.currents_pp_A = {6e-3, 1000.0};
  r.frequencies_Hz = {37};
  r.periods = 2;
  r.lanes = false;
  ModelSpec spec = builtin_model_spec();
  spec.set("circuit.branches.phi4.coil_turns", 7.2e6);
  const Model m = compile(spec);
  const SweepResult res = run_sweep(m, r);
  ASSERT_EQ(res.points.size(), 4u);
  int diverged = 0;
  for (const SweepPoint& p : res.points) {
    SimulationSettings s;
    s.temperature_C = p.temperature_C;
    s.waveform = biased_sine(p.current_pp_A, p.frequency_Hz, r.current_min_A);
    s.periods = r.periods;
    const Result full = simulate(m, s);
    EXPECT_EQ(p.diverged, full.diverged);
    EXPECT_EQ(p.error, full.error);
    diverged += p.diverged ? 1 : 0;
    if (full.diverged) continue;
    EXPECT_EQ(p.metrics.stroke_um, full.metrics.stroke_um);  // bitwise
    EXPECT_EQ(p.metrics.hysteresis_um, full.metrics.hysteresis_um);
    EXPECT_EQ(p.metrics.B_pp_T, full.metrics.B_pp_T);
    EXPECT_EQ(p.metrics.y_mean_um, full.metrics.y_mean_um);
    EXPECT_EQ(p.metrics.window_start_s, full.metrics.window_start_s);
    EXPECT_GT(p.metrics.stroke_um, 1.0);
  }
  EXPECT_EQ(diverged, 2);
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
            }).find("frequency (--frequencies) = 0 Hz: must be > 0"),
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
