// Parameter identification (issue 4): the objective (exact on synthetic data), scalar
// targets, checkpoints, the calibrated model file, and the synthetic validation: 12
// conditions (20/45/70 degC x 6/8 A x 10/100 Hz) with 1 % noise, 8 perturbed parameters,
// recovered within 2 % or their own 95 % confidence interval. Measurement files and the fit
// spec: tests/test_identify_inputs.cpp. The CLI cases (MPI, SIGKILL + resume, SIGINT) are
// ctest scripts in tests/cli/.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "identify_fixture.hpp"
#include "test_util.hpp"

using ::testing::HasSubstr;
using namespace gmasim;
using gmasim_test::ci_objective;
using gmasim_test::ci_request;
using gmasim_test::input_error;
using gmasim_test::printed_fixture;
using gmasim_test::printed_spec;
using gmasim_test::printed_text;
using gmasim_test::TempDir;

namespace {

// 8 parameters: JA k0, a0, c0 and alpha0 of rod 1, its eddy factor k_j and damping c_1,
// and the material's beta and chi_m; starts 8-30 % away from the built-in (true) values.
FitSpec eight_parameters() {
  return parse_fit_spec(R"(
[[parameter]]
name = "rod1.ja.k0_A_per_m"
lower = 1500.0
upper = 6000.0
scale = "log"
start = 3500.0
[[parameter]]
name = "rod1.ja.a0_A_per_m"
lower = 3000.0
upper = 12000.0
scale = "log"
start = 5200.0
[[parameter]]
name = "rod1.ja.c0"
lower = 0.01
upper = 0.3
scale = "log"
start = 0.06
[[parameter]]
name = "rod1.ja.alpha0"
lower = -0.08
upper = -0.005
start = -0.03
[[parameter]]
name = "rod1.k_j"
lower = 0.3
upper = 3.0
scale = "log"
start = 0.9
[[parameter]]
name = "material.beta_per_K"
lower = -4e-5
upper = -2e-6
scale = "log"
start = -1.4e-5
[[parameter]]
name = "material.chi_m"
lower = 8.0
upper = 50.0
scale = "log"
start = 17.0
[[parameter]]
name = "rod1.damping_N_s_per_m"
lower = 50.0
upper = 1500.0
scale = "log"
start = 330.0
)",
                        "eight.toml");
}

IdentifyOptions ci_options() {
  IdentifyOptions o;
  o.islands = 2;
  o.population = 12;
  o.generations = 10;
  o.migrate_every = 5;
  o.threads = 2;
  o.seed = 7;
  o.objective = ci_objective();
  return o;
}

// The model values of the eight parameters (the truth of the synthetic data).
const std::map<std::string, double> kTruth = {{"rod1.ja.k0_A_per_m", 3032.0},
                                              {"rod1.ja.a0_A_per_m", 5947.0},
                                              {"rod1.ja.c0", 0.0464},
                                              {"rod1.ja.alpha0", -0.0377},
                                              {"rod1.k_j", 1.07},
                                              {"material.beta_per_K", -1.1e-5},
                                              {"material.chi_m", 19.84},
                                              {"rod1.damping_N_s_per_m", 275.0}};

}  // namespace

// ---- objective ------------------------------------------------------------------------
TEST(Objective, ExactModelGivesZeroErrorAndUnitMappingRoundTrips) {
  const MeasurementSet set = synthesize_measurements(printed_fixture(), ci_request(0.0, 1));
  ASSERT_EQ(set.items.size(), 12u);
  FitSpec fit = eight_parameters();
  for (auto& p : fit.parameters) p.has_start = false;  // start at the model values (truth)
  const Objective obj(printed_spec(), set, fit, ci_objective());
  EXPECT_EQ(obj.dim(), 8u);
  EXPECT_EQ(obj.names()[0], "rod1.ja.k0_A_per_m");
  EXPECT_EQ(obj.names()[5], "material.beta_per_K");
  EXPECT_EQ(obj.residual_count(), 12u * 101u * 1u);  // flux ignored at flux weight 0
  const auto u = obj.start_unit();
  EXPECT_LT(obj.rms_pct(u), 1e-9);
  const auto p = obj.to_params(u);
  EXPECT_NEAR(p[0], 3032.0, 1e-9);
  EXPECT_NEAR(p[5], -1.1e-5, 1e-18);
  const auto u2 = obj.to_unit(p);
  for (std::size_t j = 0; j < u.size(); ++j) EXPECT_NEAR(u2[j], u[j], 1e-12);
  // A 1 % change of chi_m is visible.
  auto q = p;
  q[6] *= 1.01;
  EXPECT_GT(obj.rms_pct(obj.to_unit(q)), 0.05);
}

TEST(Objective, WeightsAndFluxEnterTheWeightedRms) {
  SyntheticRequest r = ci_request(0.0, 1);
  r.temperatures_C = {20};
  r.currents_pp_A = {8};
  r.frequencies_Hz = {10};
  MeasurementSet set = synthesize_measurements(printed_fixture(), r);
  // Scale the measured displacement by 1.02: every residual is 2 % of y, whatever u.
  for (double& y : set.items[0].response) y *= 1.02;
  const FitSpec fit = load_fit_spec("material.chi_m:10:30");
  const Objective obj(printed_spec(), set, fit, ci_objective());
  const double rms = obj.rms_pct(obj.start_unit());
  const auto cf = obj.condition_fits(obj.start_unit());
  ASSERT_EQ(cf.size(), 1u);
  EXPECT_NEAR(rms, cf[0].rms_pct, 1e-9);
  EXPECT_GT(rms, 0.5);
  EXPECT_LT(rms, 2.0);
  EXPECT_LT(cf[0].flux_rms_pct, 1e-9);  // the flux is exact
  ObjectiveSettings s = ci_objective();
  s.flux_weight = 1.0;  // displacement and flux count equally: the RMS drops by sqrt(2)
  const Objective obj2(printed_spec(), set, fit, s);
  EXPECT_NEAR(obj2.rms_pct(obj2.start_unit()), rms / std::sqrt(2.0), 1e-9);
}

// ---- scalar targets (how the paper's claims are calibrated, issue item 7) -------------
TEST(Identify, FrequencyResponseTargetsAreTheFrfCommandsNumbers) {
  // frf_peak_Hz and bandwidth_Hz are gmasim frf's first resonance and -3 dB point.
  const FitSpec fit = parse_fit_spec(R"(
[[parameter]]
name = "mechanics.sensor_mount.stiffness_N_per_m"
lower = 1.03e6
upper = 1.54e6
[[target]]
kind = "frf_peak_Hz"
temperature_C = 20.0
value = 1270.0
[[target]]
kind = "bandwidth_Hz"
temperature_C = 70.0
value = 2000.0
)",
                                     "frf.toml");
  ObjectiveSettings s = ci_objective();
  s.lanes = false;  // settle_at_bias itself, as run_frf
  const Objective obj(builtin_model_spec(), MeasurementSet{}, fit, s);
  const auto tf = obj.target_fits(obj.start_unit());
  ASSERT_EQ(tf.size(), 2u);
  FrfRequest r;
  r.temperatures_C = {20, 70};
  r.stepped_sine = false;
  const FrfResult frf = run_frf(load_model(""), r);
  EXPECT_DOUBLE_EQ(tf[0].simulated, frf.curves[0].first_resonance_Hz);
  EXPECT_DOUBLE_EQ(tf[1].simulated, frf.curves[1].bandwidth_3dB_Hz);
  // The bias ramps in lanes (make_states): the markers to the lanes' rounding (observed 1.8e-14
  // relative; tolerance 2e-13).
  const Objective lanes(builtin_model_spec(), MeasurementSet{}, fit, ci_objective());
  const auto tl = lanes.target_fits(lanes.start_unit());
  EXPECT_NEAR(tl[0].simulated / tf[0].simulated, 1.0, 2e-13);
  EXPECT_NEAR(tl[1].simulated / tf[1].simulated, 1.0, 2e-13);
  EXPECT_NEAR(tf[0].simulated, 1270.0, 0.01 * 1270.0);
}

// modulus_GPa (issue 18): the mean over the rods of eq. (13)'s E_G at rest at the bias, the
// number Table 6's stiffnesses pin (k_i = E A_i / l: 30 GPa); the training set, with the claim
// targets and [[by_construction]] claims, is what identify writes into [calibration].
TEST(Identify, ModulusTargetIsTheRodsMeanModulusAtRest) {
  const FitSpec fit = parse_fit_spec(R"(
[[parameter]]
name = "material.Es_Pa"
lower = 4e10
upper = 1.1e11
[[target]]
kind = "modulus_GPa"
temperature_C = 20.0
value = 30.0
[[target]]
claim = "stroke_drop_8A"
[[by_construction]]
claim = "thermal_model"
reason = "the sleeve length"
)",
                                     "modulus.toml");
  ObjectiveSettings s = ci_objective();
  s.lanes = false;  // make_state itself (lanes: Lanes.TargetRunsAndRampsMatchTheScalarPath)
  const Objective obj(builtin_model_spec(), MeasurementSet{}, fit, s);
  const auto tf = obj.target_fits(obj.start_unit());
  ASSERT_EQ(tf.size(), 2u);
  const Model m = load_model("");
  const Conditions c = make_conditions(m, 20.0);
  const State st = make_state(m, c, 1.0);
  double E = 0.0;
  for (const auto& r : st.rods) E += r.E_Pa;
  EXPECT_DOUBLE_EQ(tf[0].simulated, E / 3.0 * 1e-9);
  EXPECT_EQ(fitted_claims(fit), (std::vector<std::string>{"stroke_drop_8A", "thermal_model"}));
  EXPECT_THROW(parse_fit_spec("[[parameter]]\nname = \"material.Es_Pa\"\nlower = 4e10\nupper = "
                              "1.1e11\n[[by_construction]]\nclaim = \"thermal_model\"\n",
                              "noreason.toml"),
               InputError);
}

TEST(Identify, ScalarTargetsAloneCalibrateAParameter) {
  // Target: the stroke the built-in model gives at 70 degC; start chi_m 30 % off. The target
  // is simulated as the fit simulates scalar targets (the claims' step, 3 periods: issue 37),
  // so the fit recovers Table 5's chi_m.
  ModelSpec spec = printed_spec();
  SimulationSettings ss;
  ss.temperature_C = 70;
  ss.waveform = biased_sine(8.0, 10.0);
  ss.periods = ObjectiveSettings{}.target_periods;
  ss.dt_s = claim_dt(ss.waveform);
  const Result ref = simulate(printed_fixture(), ss);
  ASSERT_TRUE(ref.has_metrics);
  FitSpec fit = parse_fit_spec(fmt::format(R"(
[[parameter]]
name = "material.chi_m"
lower = 8.0
upper = 50.0
scale = "log"
start = 26.0
[[target]]
kind = "stroke_um"
temperature_C = 70.0
current_pp_A = 8.0
frequency_Hz = 10.0
value = {:.17g}
[[target]]
kind = "resonance_Hz"
temperature_C = 20.0
value = 5000.0
weight = 1e-6
)",
                                           ref.metrics.stroke_um),
                               "targets.toml");
  IdentifyOptions o = ci_options();
  o.islands = 1;
  o.population = 8;
  o.generations = 2;
  o.migrate_every = 2;
  const IdentifyResult r = identify(spec, MeasurementSet{}, fit, o);
  ASSERT_EQ(r.targets.size(), 2u);
  EXPECT_NEAR(r.parameters[0].value, 19.84, 0.02);
  EXPECT_NEAR(r.targets[0].simulated, ref.metrics.stroke_um, 1e-3);
  EXPECT_GT(r.targets[1].simulated, 1000.0);  // eq. (15) modes of Table 6: kHz
  EXPECT_LT(r.targets[1].simulated, 20000.0);
}

// pso_gen: a generation's particles go to the batch fitness evaluator (PoolBfe: their records
// in shared SIMD lanes). The search improves on the start, spends whole populations (pagmo's
// pso_gen evaluates its swarm more than once a generation: 337 here, 14 swarms an island and
// the start model), and gives the same bits on 1 and 2 threads (a batch's values are
// rms_pct()'s point by point: ObjectiveBatch.*).
TEST(Identify, ParticleSwarmEvaluatesItsGenerationsInBatches) {
  const MeasurementSet set = synthesize_measurements(printed_fixture(), ci_request(0.0, 1));
  IdentifyOptions o = ci_options();
  o.algorithm = "pso_gen";
  o.generations = 6;
  o.migrate_every = 3;
  o.refine_iterations = 0;
  o.profile = false;
  const IdentifyResult a = identify(printed_spec(), set, eight_parameters(), o);
  o.threads = 1;
  const IdentifyResult b = identify(printed_spec(), set, eight_parameters(), o);
  EXPECT_LT(a.ga_rms_pct, a.start_rms_pct);
  EXPECT_EQ((a.stage_evaluations.search - 1) % (2L * 12L), 0L);  // whole swarms on 2 islands
  EXPECT_GE(a.stage_evaluations.search, 2L * 12L * (6L + 1L) + 1L);
  EXPECT_EQ(a.stage_evaluations.search, b.stage_evaluations.search);
  EXPECT_EQ(a.ga_rms_pct, b.ga_rms_pct);  // bitwise
  EXPECT_EQ(a.unit_optimum, b.unit_optimum);
  std::printf("pso_gen: RMS %.3g %% at the start, %.3g %% after 6 generations\n", a.start_rms_pct,
              a.ga_rms_pct);
}

// The island algorithms in one list (kIslandAlgorithms): the options' check and its message, the
// archipelago's factory and the CLI's choices read it. Every listed name runs a search; a name
// not in it is refused before anything runs, with the list in the message.
TEST(Identify, IslandAlgorithmsAreOneList) {
  EXPECT_EQ(island_algorithm_list(), "sga, de, sade, cmaes or pso_gen");
  EXPECT_FALSE(is_island_algorithm("ga"));
  EXPECT_FALSE(is_island_algorithm(""));
  const MeasurementSet set = synthesize_measurements(printed_fixture(), ci_request(0.0, 1));
  IdentifyOptions o = ci_options();
  o.generations = 1;
  o.migrate_every = 1;
  o.refine_iterations = 0;
  o.profile = false;
  for (const std::string_view name : kIslandAlgorithms) {
    EXPECT_TRUE(is_island_algorithm(name));
    o.algorithm = std::string(name);
    const IdentifyResult r = identify(printed_spec(), set, eight_parameters(), o);
    EXPECT_GT(r.stage_evaluations.search, 1L) << name;
    EXPECT_LE(r.ga_rms_pct, r.start_rms_pct) << name;
  }
  o.algorithm = "ga";
  try {
    (void)identify(printed_spec(), set, eight_parameters(), o);
    ADD_FAILURE() << "--algorithm ga was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--algorithm ga: must be sga, de, sade, cmaes or pso_gen"),
              std::string::npos)
        << e.what();
  }
}

// ---- synthetic validation ---------------------------------------------------------------
TEST(Identify, NoiseFreeDataRecoverTheTruthExactly) {
  const MeasurementSet set = synthesize_measurements(printed_fixture(), ci_request(0.0, 1));
  const IdentifyResult r = identify(printed_spec(), set, eight_parameters(), ci_options());
  EXPECT_LT(r.rms_pct, 1e-5);
  for (const auto& p : r.parameters) EXPECT_NEAR(p.value / kTruth.at(p.name), 1.0, 1e-4) << p.name;
}

TEST(Identify, SyntheticTwelveConditionsRecoverEightParameters) {
  // The issue's validation, CI version: 1 % Gaussian noise (sigma = 1 % of each condition's
  // p-p), noise seed 2. Over noise seeds 1..6 the criterion held for 5: the intervals are
  // 95 % intervals, so a determined parameter falls outside now and then (seed 1: k_j at
  // 2.2 sigma) -- the test pins one seed; examples/identify_synthetic runs more.
  const auto t0 = std::chrono::steady_clock::now();
  const MeasurementSet set = synthesize_measurements(printed_fixture(), ci_request(1.0, 2));
  const IdentifyResult r = identify(printed_spec(), set, eight_parameters(), ci_options());
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LE(r.rms_pct, 1.5);
  EXPECT_GT(r.start_rms_pct, 3.0);
  ASSERT_EQ(r.parameters.size(), 8u);
  for (const auto& p : r.parameters) {
    const double t = kTruth.at(p.name);
    const bool within_2pct = std::fabs(p.value - t) <= 0.02 * std::fabs(t);
    const bool within_ci = p.ci_low <= t && t <= p.ci_high;
    EXPECT_TRUE(within_2pct || within_ci) << p.name << " = " << p.value << ", truth " << t
                                          << ", 95 % CI [" << p.ci_low << ", " << p.ci_high << "]";
  }
  // The data determine a0, alpha0, beta and chi_m well: their intervals are narrow.
  for (const auto& p : r.parameters) {
    if (p.name == "rod1.ja.a0_A_per_m" || p.name == "material.chi_m" ||
        p.name == "material.beta_per_K") {
      EXPECT_TRUE(p.determined) << p.name;
      EXPECT_LT((p.ci_high - p.ci_low) / std::fabs(p.value), 0.2) << p.name;
    }
  }
  ASSERT_EQ(r.correlation.size(), 8u);
  EXPECT_NEAR(r.correlation[0][0], 1.0, 1e-12);
  EXPECT_NEAR(r.correlation[2][0], r.correlation[0][2], 1e-12);
  ASSERT_EQ(r.conditions.size(), 12u);
  for (const auto& c : r.conditions) EXPECT_LT(c.rms_pct, 1.5) << c.label;
  EXPECT_FALSE(r.history.empty());
  std::printf("[ synthetic ] RMS %.4f %% (start %.3f %%), %ld evaluations, %.1f s\n", r.rms_pct,
              r.start_rms_pct, r.evaluations, wall);
  for (const auto& p : r.parameters) {
    std::printf("[ synthetic ] %-26s truth %-10.6g fitted %-12.6g CI [%.6g, %.6g]\n",
                p.name.c_str(), kTruth.at(p.name), p.value, p.ci_low, p.ci_high);
  }

  // The calibrated model file: loads, carries the fitted values and their provenance.
  FitProvenance prov;
  prov.command = "gmasim identify --data manifest.toml --fit eight.toml --out fitted.toml";
  prov.data = "manifest.toml";
  prov.fit = "eight.toml";
  const std::string text = fitted_model_toml(printed_text(), printed_spec(), r, prov);
  const ModelSpec back = parse_model_spec(text, "fitted.toml");
  for (const auto& p : r.parameters) {
    EXPECT_NEAR(back.get(p.name) / p.value, 1.0, 1e-11) << p.name;
    EXPECT_THAT(back.params.at(p.name).provenance, HasSubstr("identified: gmasim identify"));
  }
  EXPECT_THAT(text, HasSubstr("# command: gmasim identify --data manifest.toml"));
  EXPECT_EQ(back.get("rod2.ja.k0_A_per_m"), 4808.0);  // untouched values stay
  const std::string json = fit_report_json(r, prov);
  EXPECT_THAT(json, HasSubstr("\"ci95\": ["));
  EXPECT_THAT(json, HasSubstr("\"correlation\": ["));
  EXPECT_THAT(fit_report_markdown(r, prov), HasSubstr("## Correlation matrix"));
}

TEST(Identify, CheckpointRoundTripAndResumeNeverWorse) {
  TempDir d;
  SyntheticRequest rq = ci_request(1.0, 4);
  rq.temperatures_C = {20, 70};
  rq.currents_pp_A = {8};
  const MeasurementSet set = synthesize_measurements(printed_fixture(), rq);
  const FitSpec fit = load_fit_spec("rod1.ja.k0_A_per_m:1500:6000:log,material.chi_m:8:50:log");
  IdentifyOptions o = ci_options();
  o.refine = false;
  o.generations = 6;
  o.migrate_every = 3;
  o.checkpoint_every = 3;
  o.checkpoint_path = (d.path() / "ck.txt").string();
  const IdentifyResult a = identify(printed_spec(), set, fit, o);
  EXPECT_EQ(a.generations_done, 6);
  std::ifstream in(o.checkpoint_path);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "gmasim-identify-checkpoint 1");
  // Continue to 12 generations from the checkpoint.
  IdentifyOptions o2 = o;
  o2.resume_path = o.checkpoint_path;
  o2.generations = 12;
  const IdentifyResult b = identify(printed_spec(), set, fit, o2);
  EXPECT_TRUE(b.resumed);
  EXPECT_EQ(b.generations_done, 12);
  EXPECT_LE(b.rms_pct, a.rms_pct);
  EXPECT_GE(b.history.size(), a.history.size());
  // Issue 41: a second checkpoint appended to the first is refused, not resumed from its first
  // copy (a truncated one already was).
  std::stringstream whole;
  whole << std::ifstream(o.checkpoint_path).rdbuf();
  std::ofstream(o.checkpoint_path) << whole.str() << whole.str();
  EXPECT_THAT(input_error([&] { (void)identify(printed_spec(), set, fit, o2); }),
              HasSubstr("text after the 'end' line ('gmasim-identify-checkpoint 1'): a second "
                        "checkpoint appended"));
  std::ofstream(o.checkpoint_path) << whole.str() << "\n\n";  // trailing blank lines are fine
  EXPECT_TRUE(identify(printed_spec(), set, fit, o2).resumed);
  // Another fit spec cannot resume it.
  IdentifyOptions o3 = o2;
  const FitSpec other = load_fit_spec("rod1.ja.k0_A_per_m:1500:6000:log,material.chi_m:8:60:log");
  EXPECT_THAT(input_error([&] { (void)identify(printed_spec(), set, other, o3); }),
              HasSubstr("other fitted parameters or bounds"));
  std::ofstream(o.checkpoint_path) << "gmasim-identify-checkpoint 1\nfp_parameters x\n";
  EXPECT_THAT(input_error([&] { (void)identify(printed_spec(), set, fit, o3); }),
              HasSubstr("damaged checkpoint"));
}

TEST(Identify, StopFlagEndsCleanlyWithTheBestSoFar) {
  SyntheticRequest rq = ci_request(1.0, 4);
  rq.temperatures_C = {20};
  rq.frequencies_Hz = {100};
  const MeasurementSet set = synthesize_measurements(printed_fixture(), rq);
  const FitSpec fit = load_fit_spec("material.chi_m:8:50:log");
  std::atomic<bool> stop{true};  // as if SIGINT came during the first population
  IdentifyOptions o = ci_options();
  o.generations = 100;
  o.stop = &stop;
  const IdentifyResult r = identify(printed_spec(), set, fit, o);
  EXPECT_TRUE(r.interrupted);
  // Issue 19, item 4: the stop takes effect within one evaluation, so not even the first
  // population is finished (it used to run the whole first epoch: generations_done ==
  // migrate_every); the best so far is the start model.
  EXPECT_EQ(r.generations_done, 0);
  EXPECT_LE(r.rms_pct, r.start_rms_pct);
  EXPECT_EQ(r.parameters.size(), 1u);
}
