// Identification on a real measured loop (issue 20; issue 22 item 4): the fitted offsets
// reported in the record's unit, a field column in kA/m read or refused, a record started
// from a given remanence, the profile stage's budget and the stages' evaluations, the written
// point being the best any stage found, and a search that does not depend on the threads.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "test_util.hpp"

using ::testing::HasSubstr;
using ::testing::Not;
using namespace gmasim;

using gmasim_test::input_error;
using gmasim_test::TempDir;

namespace {

using gmasim_test::max_abs_diff;
using gmasim_test::range;

const ModelSpec& single_rod() {
  static const ModelSpec s =
      load_model_spec(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod.toml");
  return s;
}

// The quasi-static strain-vs-field loop of examples/strain_loop (one rod, 20 degC, the field
// of a 12 A p-p sine from -6 A) from the single-rod template, noise-free unless asked.
SyntheticRequest strain_loop(int samples, double noise_pct = 0.0) {
  SyntheticRequest r;
  r.temperatures_C = {20};
  r.currents_pp_A = {12};
  r.current_min_A = -6;
  r.quasi_static = true;
  r.drive = DriveInput::Field;
  r.response = ResponseOutput::Strain;
  r.samples_per_period = samples;
  r.noise_pct = noise_pct;
  r.with_flux = false;
  return r;
}

// A quasi-static field record along 0 -> +A -> -A -> 0 (n samples per quarter): the
// butterfly a lab records after the previous cycle left the rod at its negative remanence.
Measurement butterfly(double A, int n) {
  Measurement m;
  m.path = "butterfly.csv";
  m.condition.temperature_C = 20.0;
  m.condition.quasi_static = true;
  m.condition.label = "butterfly";
  m.drive_kind = DriveInput::Field;
  m.response_kind = ResponseOutput::Strain;
  const double path[] = {0.0, A, 0.0, -A, 0.0};
  for (int q = 0; q < 4; ++q)
    for (int k = q == 0 ? 0 : 1; k <= n; ++k) {
      m.drive.push_back(path[q] + (path[q + 1] - path[q]) * k / n);
      m.t_s.push_back(static_cast<double>(m.t_s.size()));
      m.response.push_back(0.0);
    }
  return m;
}

FitSpec fit_of(std::vector<FitParameter> p) {
  FitSpec f;
  f.parameters = std::move(p);
  return f;
}

}  // namespace

// ---- offsets and units --------------------------------------------------------------------
// The least-squares offset of a record written 123 ppm off is reported as such, in ppm, in
// the report's JSON (whose keys carry the record's unit, not "um").
TEST(RealLoop, FittedOffsetIsReportedInTheRecordsUnit) {
  SyntheticRequest r = strain_loop(40);
  r.offset = OffsetMode::Fitted;
  r.response_offset = 123.0;
  const MeasurementSet set = synthesize_measurements(compile(single_rod()), r);
  const FitSpec fit =
      fit_of({{"rod.ja.k0_A_per_m", 1000.0, 9000.0, ParamScale::Log, false, 0.0, 1}});
  const Objective obj(single_rod(), set, fit, ObjectiveSettings{});
  IdentifyResult res;
  res.conditions = obj.condition_fits(obj.start_unit());
  ASSERT_EQ(res.conditions.size(), 1u);
  const ConditionFit& c = res.conditions[0];
  EXPECT_EQ(c.response_unit, "ppm");
  EXPECT_NEAR(c.offset, 123.0, 1e-6);  // noise-free: the exact shift (observed 1e-9)
  EXPECT_LT(c.rms_pct, 1e-6);
  const std::string json = fit_report_json(res, FitProvenance{});
  EXPECT_THAT(json, HasSubstr("\"pp_ppm\""));
  EXPECT_THAT(json, HasSubstr("\"rms_ppm\""));
  EXPECT_THAT(json, HasSubstr("\"max_err_ppm\""));
  EXPECT_THAT(json, HasSubstr("\"offset_ppm\": 123"));
  EXPECT_THAT(json, Not(HasSubstr("_um\"")));
  EXPECT_THAT(fit_report_markdown(res, FitProvenance{}), HasSubstr("fitted +123 ppm"));
}

// ---- field units --------------------------------------------------------------------------
TEST(RealLoop, FieldInKiloampsPerMetreIsReadOrRefused) {
  TempDir dir;
  const MeasurementSet set = synthesize_measurements(compile(single_rod()), strain_loop(24));
  const Measurement& a = set.items[0];
  std::string kA = "# temperature_C = 20\nfield_kA_per_m,strain_ppm\n";
  std::string wrong = "# temperature_C = 20\nfield_A_per_m,strain_ppm\n";
  for (std::size_t i = 0; i < a.drive.size(); ++i) {
    kA += fmt::format("{:.17g},{:.17g}\n", a.drive[i] / 1e3, a.response[i]);
    wrong += fmt::format("{:.17g},{:.17g}\n", a.drive[i] / 1e3, a.response[i]);
  }
  // A column named in kA/m is read in A/m: the same record, the same (exact) fit.
  const Measurement back = load_measurement_csv(dir.write("kA.csv", kA));
  EXPECT_EQ(back.drive_kind, DriveInput::Field);
  EXPECT_EQ(back.drive_header, "field_kA_per_m");
  for (std::size_t i = 0; i < a.drive.size(); ++i)
    EXPECT_NEAR(back.drive[i], a.drive[i], 1e-9 * std::fabs(a.drive[i]) + 1e-9);
  const FitSpec fit =
      fit_of({{"rod.ja.k0_A_per_m", 1000.0, 9000.0, ParamScale::Log, false, 0.0, 1}});
  MeasurementSet ok{"", {back}};
  const Objective obj(single_rod(), ok, fit, ObjectiveSettings{});
  EXPECT_LT(obj.rms_pct(obj.start_unit()), 1e-3);
  // The same numbers under field_A_per_m are 1000x too small: refused, naming the column,
  // the rule and the fix.
  MeasurementSet bad{"", {load_measurement_csv(dir.write("wrong.csv", wrong))}};
  const std::string msg = input_error([&] { (void)Objective(single_rod(), bad, fit); });
  EXPECT_THAT(msg, HasSubstr("wrong.csv"));
  EXPECT_THAT(msg, HasSubstr("column field_A_per_m"));
  EXPECT_THAT(msg, HasSubstr("anhysteretic shape field a"));
  EXPECT_THAT(msg, HasSubstr("name the column field_kA_per_m"));
  // A Preisach rod has no anhysteretic shape a (its JA table is not read: a = 0 let every
  // record pass before): the law names its own field, the hysterons' median coercive field.
  const ModelSpec pre =
      load_model_spec(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod_preisach.toml");
  const FitSpec pre_fit =
      fit_of({{"rod.preisach.Hc0_A_per_m", 500.0, 9000.0, ParamScale::Log, false, 0.0, 1}});
  const std::string pmsg = input_error([&] { (void)Objective(pre, bad, pre_fit); });
  EXPECT_THAT(pmsg, HasSubstr("median coercive field H_c"));
  EXPECT_THAT(pmsg, HasSubstr("name the column field_kA_per_m"));
  // Both field columns at once are refused.
  EXPECT_THAT(input_error([&] {
                (void)load_measurement_csv(
                    dir.write("both.csv",
                              "# temperature_C = 20\nfield_kA_per_m,field_A_per_m,"
                              "strain_ppm\n1,1000,0\n2,2000,1\n3,3000,2\n4,4000,3\n"));
              }),
              HasSubstr("one drive column"));
}

// ---- the initial magnetic state -----------------------------------------------------------
// A butterfly started at negative remanence is the compared pass after one pass of the same
// drive from the demagnetised state (which leaves the rod there); from the demagnetised
// state its first branch differs (the key has teeth).
TEST(RealLoop, NegativeRemanenceStartIsTheLoopAfterABipolarCycle) {
  const Model m = compile(single_rod());
  const ObjectiveSettings s;
  Measurement rem = butterfly(60e3, 40);
  rem.condition.initial_state = InitialState::NegativeRemanence;
  Measurement pre = butterfly(60e3, 40);
  pre.condition.precycles = 1;
  Measurement virgin = butterfly(60e3, 40);
  std::vector<double> y_rem, y_pre, y_virgin;
  simulate_measurement(m, rem, s, y_rem);
  simulate_measurement(m, pre, s, y_pre);
  simulate_measurement(m, virgin, s, y_virgin);
  const double d = max_abs_diff(y_rem, y_pre), pp = range(y_pre);
  std::printf("[ initial_state ] max |negative remanence - pre-cycled| = %.3g ppm of %.4g ppm\n", d,
              pp);
  EXPECT_LT(d, 3e-8 * pp);  // only the increments differ (observed 2.8e-9 of the p-p)
  // The demagnetised start's first branch differs (observed 3.6 ppm, 4.4e-3 of the p-p).
  const double dv = max_abs_diff(y_virgin, y_pre);
  std::printf("[ initial_state ] max |demagnetised - pre-cycled| = %.3g ppm\n", dv);
  EXPECT_GT(dv, 1e-3 * pp);
  // Positive remanence mirrors the field: the strain (even in M) is the same loop, run
  // with -H.
  Measurement pos = butterfly(-60e3, 40);
  pos.condition.initial_state = InitialState::PositiveRemanence;
  std::vector<double> y_pos;
  simulate_measurement(m, pos, s, y_pos);
  EXPECT_LT(max_abs_diff(y_pos, y_rem), 1e-6 * pp);
}

// The key is read from a CSV file, round-trips, and makes every sample compared.
TEST(RealLoop, InitialStateKeyRoundTripsAndComparesEverySample) {
  TempDir dir;
  SyntheticRequest r = strain_loop(24);
  r.initial_state = InitialState::NegativeRemanence;
  r.periods = 1;
  const MeasurementSet set = synthesize_measurements(compile(single_rod()), r);
  const Measurement back =
      load_measurement_csv(dir.write("rem.csv", measurement_csv(set.items[0])));
  EXPECT_EQ(back.condition.initial_state, InitialState::NegativeRemanence);
  EXPECT_EQ(back.condition.compare_from_s, 0.0);
  EXPECT_THAT(input_error([&] {
                (void)load_measurement_csv(
                    dir.write("bad.csv",
                              "# temperature_C = 20\n# initial_state = remanent\n"
                              "field_A_per_m,strain_ppm\n0,0\n1e4,1\n2e4,2\n3e4,3\n"));
              }),
              HasSubstr("must be demagnetised, negative_remanence or positive_remanence"));
}

// ---- identify's stages --------------------------------------------------------------------
namespace {

// Three constants of the loop; k0's bounds exclude the truth (3032 A/m), so the optimum sits
// on a bound and its interval is a profile.
FitSpec three_constants() {
  return fit_of({{"rod.ja.k0_A_per_m", 3500.0, 9000.0, ParamScale::Log, false, 0.0, 1},
                 {"rod.ja.a0_A_per_m", 2000.0, 18000.0, ParamScale::Log, true, 4000.0, 2},
                 {"material.lambda_s", 5e-4, 2.5e-3, ParamScale::Log, true, 1.5e-3, 4}});
}

// Cheap, exact-model settings: a current-driven quasi-static strain loop in 100 increments.
ObjectiveSettings cheap() {
  ObjectiveSettings s;
  s.quasi_static_increments = 100;
  return s;
}

IdentifyOptions small_search() {
  IdentifyOptions o;
  o.islands = 2;
  o.population = 8;
  o.generations = 4;
  o.migrate_every = 2;
  o.threads = 2;
  o.seed = 3;
  o.objective = cheap();
  return o;
}

const MeasurementSet& noisy_loop() {
  static const MeasurementSet set = [] {
    SyntheticRequest r = strain_loop(16, 0.5);
    r.drive = DriveInput::Current;
    r.objective = cheap();
    return synthesize_measurements(compile(single_rod()), r);
  }();
  return set;
}

long stage_sum(const StageEvaluations& s) { return s.search + s.refine + s.covariance + s.profile; }

}  // namespace

// By default the profile spends no more evaluations than the search; the stages add up to the
// total; a budget below what the profile spends without a limit stops it there (the budget has
// teeth).
TEST(RealLoop, ProfileCostsNoMoreThanTheSearchAndTheStagesAddUp) {
  IdentifyOptions o = small_search();
  o.generations = 1;  // a search cheaper than the profile it is followed by
  const IdentifyResult r = identify(single_rod(), noisy_loop(), three_constants(), o);
  const StageEvaluations& s = r.stage_evaluations;
  std::printf("[ stages ] %s; total %ld\n", stage_text(s).c_str(), r.evaluations);
  EXPECT_EQ(stage_sum(s), r.evaluations);
  EXPECT_EQ(s.profile_budget, s.search);
  EXPECT_LE(s.profile, s.search);  // observed 43 of 49
  EXPECT_GT(s.profile, 0);
  EXPECT_EQ(r.parameters[0].ci_method, "profile");
  EXPECT_TRUE(r.parameters[0].at_bound);
  o.profile_evaluations = 0;  // no limit
  const IdentifyResult u = identify(single_rod(), noisy_loop(), three_constants(), o);
  std::printf("[ stages ] no limit: %s\n", stage_text(u.stage_evaluations).c_str());
  EXPECT_GT(u.stage_evaluations.profile, 0);  // observed 43
  EXPECT_EQ(u.stage_evaluations.profile_budget, -1);
  EXPECT_EQ(stage_sum(u.stage_evaluations), u.evaluations);
  o.profile_evaluations = u.stage_evaluations.profile / 2;
  const IdentifyResult h = identify(single_rod(), noisy_loop(), three_constants(), o);
  std::printf("[ stages ] half: %s\n", stage_text(h.stage_evaluations).c_str());
  EXPECT_LE(h.stage_evaluations.profile, o.profile_evaluations);
  EXPECT_LT(h.stage_evaluations.profile, u.stage_evaluations.profile);
  EXPECT_EQ(stage_sum(h.stage_evaluations), h.evaluations);
}

// The written point is the best any stage evaluated: its error is the objective's there, and
// no stage's best (search, refinement, profile) is lower.
TEST(RealLoop, WrittenPointIsTheBestAnyStageFound) {
  IdentifyOptions o = small_search();
  o.refine_iterations = 1;  // a refinement cut short: the profile's refits go further
  o.profile_evaluations = 0;
  const FitSpec fit = three_constants();
  const IdentifyResult r = identify(single_rod(), noisy_loop(), fit, o);
  const Objective obj(single_rod(), noisy_loop(), fit, o.objective);
  std::printf("[ best point ] RMS %.6g %% found by the %s (search %.6g %%)\n", r.rms_pct,
              r.best_found_by.c_str(), r.ga_rms_pct);
  EXPECT_EQ(r.best_found_by, "profile");
  EXPECT_NEAR(obj.rms_pct(r.unit_optimum), r.rms_pct, 1e-12 * r.rms_pct);
  for (const auto& h : r.history) EXPECT_LE(r.rms_pct, h.best_rms_pct);
  EXPECT_LT(r.rms_pct, r.ga_rms_pct);
}

// The search is the same with 1 or 2 worker threads (3 islands: migration both ways along
// the ring, the neighbour chosen by a hash, not by a clock).
TEST(RealLoop, SearchDoesNotDependOnTheThreads) {
  IdentifyOptions o = small_search();
  o.islands = 3;
  o.generations = 6;
  o.refine = false;
  o.threads = 1;
  const IdentifyResult a = identify(single_rod(), noisy_loop(), three_constants(), o);
  o.threads = 2;
  const IdentifyResult b = identify(single_rod(), noisy_loop(), three_constants(), o);
  EXPECT_EQ(a.ga_rms_pct, b.ga_rms_pct);
  EXPECT_EQ(a.unit_optimum, b.unit_optimum);
  EXPECT_EQ(a.evaluations, b.evaluations);
  ASSERT_EQ(a.history.size(), b.history.size());
  for (std::size_t k = 0; k < a.history.size(); ++k)
    EXPECT_EQ(a.history[k].best_rms_pct, b.history[k].best_rms_pct);
}
