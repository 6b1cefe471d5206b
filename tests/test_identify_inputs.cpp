// Parameter identification (issue 4), its inputs: measurement files and manifests with their
// errors (file:line), a written measurement set read back, and the fit spec.
// The objective and the search: tests/test_identify.cpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "identify_fixture.hpp"
#include "test_util.hpp"

using ::testing::HasSubstr;
using namespace gmasim;
using gmasim_test::ci_request;
using gmasim_test::input_error;
using gmasim_test::printed_fixture;
using gmasim_test::printed_spec;
using gmasim_test::TempDir;

namespace {

const char* kHead =
    "# temperature_C = 20\n# frequency_Hz = 10\n# current_pp_A = 8\n"
    "t_s,current_A,displacement_um\n";

std::string rows(int n, double t0 = 0.0, double dt = 0.01) {
  std::string s;
  for (int k = 0; k < n; ++k)
    s += std::to_string(t0 + k * dt) + "," + std::to_string(k % 5) + "," + std::to_string(k) + "\n";
  return s;
}

}  // namespace

// ---- measurement files ----------------------------------------------------------------
TEST(Measurements, ReadsConditionFromHeaderComments) {
  TempDir d;
  const auto p = d.write("a.csv", std::string("# a free comment\n") + kHead + rows(30));
  const Measurement m = load_measurement_csv(p);
  EXPECT_EQ(m.t_s.size(), 30u);
  EXPECT_DOUBLE_EQ(m.condition.temperature_C, 20.0);
  EXPECT_DOUBLE_EQ(m.condition.frequency_Hz, 10.0);
  EXPECT_DOUBLE_EQ(m.condition.current_pp_A, 8.0);
  EXPECT_DOUBLE_EQ(m.condition.compare_from_s, 0.1);  // one period after t0
  EXPECT_EQ(m.condition.label, "a");
  EXPECT_TRUE(m.flux_T.empty());
}

TEST(Measurements, ReadsConditionFromSidecarAndFluxColumn) {
  TempDir d;
  d.write("b.toml", "temperature_C = 45.0\nlabel = \"hot\"\n");
  const auto p = d.write("b.csv",
                         "flux_T,t_s,current_A,displacement_um\n0.1,0,1,2\n0.2,1,1,2\n"
                         "0.3,2,1,2\n0.4,3,1,2\n");
  const Measurement m = load_measurement_csv(p);
  EXPECT_DOUBLE_EQ(m.condition.temperature_C, 45.0);
  EXPECT_EQ(m.condition.label, "hot");
  EXPECT_FALSE(m.periodic());
  ASSERT_EQ(m.flux_T.size(), 4u);
  EXPECT_DOUBLE_EQ(m.flux_T[2], 0.3);
  EXPECT_DOUBLE_EQ(m.t_s[3], 3.0);
}

struct BadCsv {
  const char* name;
  std::string text;
  long line;
  const char* words;
};

TEST(Measurements, RejectsBadFilesWithFileAndLine) {
  const std::vector<BadCsv> cases = {
      {"empty", "", 1, "empty file"},
      {"only comments", "# temperature_C = 20\n", 1, "no header"},
      {"non-numeric", std::string(kHead) + rows(5) + "0.5,abc,3\n", 10,
       "non-numeric value 'abc' in column current_A"},
      {"NaN", std::string(kHead) + rows(5) + "0.5,1,nan\n", 10,
       "NaN ('nan') in column displacement_um"},
      {"Inf", std::string(kHead) + "0,1,inf\n" + rows(5, 1.0), 5, "Inf"},
      {"time decreases", std::string(kHead) + rows(5) + "0.01,1,1\n", 10,
       "time 0.01 s does not increase"},
      {"duplicate timestamp", std::string(kHead) + rows(5) + "0.04,1,1\n", 10,
       "duplicate timestamp t_s = 0.04 s"},
      {"mismatched columns", std::string(kHead) + rows(5) + "0.5,1\n", 10,
       "mismatched columns: 2 cells, the header has 3"},
      {"extra column", std::string(kHead) + rows(5) + "0.5,1,2,3\n", 10,
       "mismatched columns: 4 cells"},
      {"missing column", "# temperature_C = 20\nt_s,current_A\n0,1\n", 2,
       "missing response column ('displacement_um' or 'strain_ppm')"},
      {"unknown column", "# temperature_C = 20\nt_s,current_A,displacement_um,force_N\n", 2,
       "unknown column 'force_N'"},
      {"no temperature",
       "# frequency_Hz = 10\n# current_pp_A = 8\nt_s,current_A,displacement_um\n" + rows(30), 3,
       "condition missing: temperature_C"},
      {"frequency without current",
       "# temperature_C = 20\n# frequency_Hz = 10\nt_s,current_A,displacement_um\n" + rows(30), 2,
       "condition missing: current_pp_A"},
      {"current without frequency",
       "# temperature_C = 20\n# current_pp_A = 8\nt_s,current_A,displacement_um\n" + rows(30), 2,
       "condition missing: frequency_Hz"},
      {"typo in a key", "# temprature_C = 20\nt_s,current_A,displacement_um\n" + rows(30), 1,
       "unknown condition key 'temprature_C'"},
      {"bad key value", "# temperature_C = warm\nt_s,current_A,displacement_um\n" + rows(30), 1,
       "non-numeric value 'warm'"},
      {"too short", std::string(kHead) + rows(3), 7, "at least 4 data rows"},
      {"shorter than a period", std::string(kHead) + rows(10), 4, "shorter than one period"},
  };
  for (const auto& c : cases) {
    TempDir d;
    const auto p = d.write("m.csv", c.text);
    const std::string msg = input_error([&] { (void)load_measurement_csv(p); });
    EXPECT_THAT(msg, HasSubstr(p + ":" + std::to_string(c.line) + ": ")) << c.name << ": " << msg;
    EXPECT_THAT(msg, HasSubstr(c.words)) << c.name << ": " << msg;
  }
}

TEST(Measurements, SidecarThatContradictsTheHeaderIsRejected) {
  TempDir d;
  const auto side = d.write("c.toml", "# sidecar\ntemperature_C = 70.0\n");
  const auto p = d.write("c.csv", std::string(kHead) + rows(30));
  const std::string msg = input_error([&] { (void)load_measurement_csv(p); });
  EXPECT_THAT(msg, HasSubstr(side + ":2: temperature_C = 70 contradicts temperature_C = 20 at " +
                             p + ":1"));
  d.write("c.toml", "temprature_C = 70.0\n");
  EXPECT_THAT(input_error([&] { (void)load_measurement_csv(p); }),
              HasSubstr(side + ":1: unknown condition key 'temprature_C'"));
}

TEST(Measurements, ManifestListsFilesAndWeights) {
  TempDir d;
  d.write("a.csv", std::string(kHead) + rows(30));
  d.write("b.csv", std::string(kHead) + rows(30));
  const auto man = d.write("m.toml",
                           "[[measurement]]\nfile = \"a.csv\"\nweight = 2.0\n\n"
                           "[[measurement]]\nfile = \"b.csv\"\n");
  const MeasurementSet set = load_manifest(man);
  ASSERT_EQ(set.items.size(), 2u);
  EXPECT_DOUBLE_EQ(set.items[0].weight, 2.0);
  EXPECT_DOUBLE_EQ(set.items[1].weight, 1.0);

  const auto missing = d.write(
      "x.toml", "[[measurement]]\nfile = \"a.csv\"\n\n[[measurement]]\nfile = \"nope.csv\"\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(missing); }),
              HasSubstr(missing + ":4: measurement file 'nope.csv' does not exist"));
  const auto weight = d.write("w.toml", "[[measurement]]\nfile = \"a.csv\"\nweight = -1\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(weight); }),
              HasSubstr(weight + ":3: weight = -1: must be > 0"));
  const auto twice =
      d.write("t.toml", "[[measurement]]\nfile = \"a.csv\"\n[[measurement]]\nfile = \"a.csv\"\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(twice); }), HasSubstr("listed twice"));
  const auto key = d.write("k.toml", "[[measurement]]\nfile = \"a.csv\"\nweigth = 1\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(key); }),
              HasSubstr(key + ":3: unknown key 'weigth'"));
  const auto none = d.write("n.toml", "# nothing\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(none); }),
              HasSubstr("no [[measurement]] entries"));
  // A bad file inside a manifest is reported with its own file:line.
  const auto bad = d.write("bad.csv", std::string(kHead) + rows(5) + "0.01,1,1\n");
  const auto man2 = d.write("m2.toml", "[[measurement]]\nfile = \"bad.csv\"\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(man2); }), HasSubstr(bad + ":10: time 0.01 s"));
}

TEST(Measurements, WrittenSetReadsBackBitForBit) {
  TempDir d;
  SyntheticRequest r = ci_request(1.0, 3);
  r.temperatures_C = {20, 70};
  r.currents_pp_A = {8};
  r.frequencies_Hz = {100};
  const MeasurementSet set = synthesize_measurements(printed_fixture(), r);
  write_measurement_set(set, d.path().string());
  const MeasurementSet back = load_manifest((d.path() / "manifest.toml").string());
  ASSERT_EQ(back.items.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.items[i].t_s, set.items[i].t_s);
    EXPECT_EQ(back.items[i].drive, set.items[i].drive);
    EXPECT_EQ(back.items[i].response, set.items[i].response);
    EXPECT_EQ(back.items[i].flux_T, set.items[i].flux_T);
    EXPECT_EQ(back.items[i].condition.compare_from_s, set.items[i].condition.compare_from_s);
  }
}

// ---- fit spec -------------------------------------------------------------------------
TEST(FitSpec, InlineAndTomlForms) {
  const FitSpec a = load_fit_spec("rod1.ja.k0_A_per_m:1000:8000:log,material.chi_m:5:40");
  ASSERT_EQ(a.parameters.size(), 2u);
  EXPECT_EQ(a.parameters[0].scale, ParamScale::Log);
  EXPECT_EQ(a.parameters[1].scale, ParamScale::Linear);
  EXPECT_DOUBLE_EQ(a.parameters[1].upper, 40.0);
  const FitSpec b = parse_fit_spec(
      "[[parameter]]\nname = \"material.beta_per_K\"\nlower = -3e-5\nupper = -1e-6\nscale = "
      "\"log\"\n"
      "[[target]]\nkind = \"stroke_change_pct\"\ntemperature_C = 70.0\ncurrent_pp_A = 6.0\n"
      "frequency_Hz = 10.0\nvalue = -11.3\n",
      "spec.toml");
  ASSERT_EQ(b.targets.size(), 1u);
  EXPECT_EQ(b.targets[0].kind, TargetKind::StrokeChangePct);
  EXPECT_DOUBLE_EQ(b.targets[0].reference_temperature_C, 20.0);
  EXPECT_DOUBLE_EQ(b.targets[0].scale, 11.3);
}

TEST(FitSpec, RejectsBadSpecsWithLine) {
  EXPECT_THAT(input_error([] {
                (void)parse_fit_spec("[[parameter]]\nname = \"x\"\nlower = 2.0\nupper = 1.0\n",
                                     "s.toml");
              }),
              HasSubstr("s.toml:1: parameter x: lower bound 2 must be < upper bound 1"));
  EXPECT_THAT(input_error([] {
                (void)parse_fit_spec(
                    "[[parameter]]\nname = \"x\"\nlower = -1.0\nupper = 1.0\nscale = \"log\"\n",
                    "s.toml");
              }),
              HasSubstr("log scale needs bounds of one sign"));
  EXPECT_THAT(input_error([] {
                (void)parse_fit_spec(
                    "[[parameter]]\nname = \"x\"\nlower = 1.0\nupper = 2.0\nuper = 3\n", "s.toml");
              }),
              HasSubstr("s.toml:5: unknown key 'uper' in [[parameter]]"));
  EXPECT_THAT(input_error([] { (void)parse_fit_spec("[[target]]\nkind = \"speed\"\n", "s.toml"); }),
              HasSubstr("s.toml:1: [[target]]: kind must be one of"));
  EXPECT_THAT(input_error([] { (void)load_fit_spec("rod1.ja.k0_A_per_m:1000"); }),
              HasSubstr("has 2 fields"));
  // Names and bounds are checked against the model.
  const MeasurementSet none;
  FitSpec t = parse_fit_spec(
      "[[parameter]]\nname = \"rod1.ja.k9\"\nlower = 1.0\nupper = 2.0\n"
      "[[target]]\nkind = \"resonance_Hz\"\ntemperature_C = 20.0\nvalue = 1270.0\n",
      "t.toml");
  EXPECT_THAT(input_error([&] { Objective(printed_spec(), none, t); }),
              HasSubstr("unknown parameter 'rod1.ja.k9'"));
  t.parameters[0].name = "rod1.ja.c0";
  t.parameters[0].lower = 0.5;
  t.parameters[0].upper = 1.5;  // c0 must be in [0, 1)
  EXPECT_THAT(input_error([&] { Objective(printed_spec(), none, t); }),
              HasSubstr("t.toml:1: parameter rod1.ja.c0: bound 1.5 is not a valid model value"));
}

// ---- issue 41: what identify says while and before it searches ----------------------------
namespace {

// One noise-free 8 A, 10 Hz record of the printed fixture at T.
MeasurementSet one_record_at(double T) {
  SyntheticRequest rq = ci_request(0.0, 5);
  rq.temperatures_C = {T};
  rq.currents_pp_A = {8};
  rq.frequencies_Hz = {10};
  return synthesize_measurements(printed_fixture(), rq);
}

IdentifyOptions tiny_search() {
  IdentifyOptions o;
  o.islands = 1;
  o.population = 8;
  o.generations = 2;
  o.threads = 1;
  o.seed = 3;
  o.objective = gmasim_test::ci_objective();
  return o;
}

}  // namespace

// The profile stage (minutes on a measured loop) reports each solve: the parameter being
// profiled, k of n. chi_m's truth (19.84) is above the bounds, so the optimum sits on the upper
// bound and its interval is profiled.
TEST(IdentifyProgress, TheProfileStageReportsEachSolve) {
  const MeasurementSet set = one_record_at(20.0);
  const FitSpec fit = load_fit_spec("material.chi_m:8:15:log");
  IdentifyOptions o = tiny_search();
  std::vector<IdentifyProgress> seen;
  o.progress = [&](const IdentifyProgress& p) { seen.push_back(p); };
  const IdentifyResult r = identify(printed_spec(), set, fit, o);
  ASSERT_EQ(r.parameters.size(), 1u);
  EXPECT_EQ(r.parameters[0].ci_method, "profile");
  long profiles = 0;
  for (const auto& p : seen)
    if (p.phase == "profile") {
      ++profiles;
      EXPECT_EQ(p.parameter, "material.chi_m");
      EXPECT_EQ(p.generation, 1);
      EXPECT_EQ(p.generations, 1);
      EXPECT_GT(p.evaluations, 0);
    }
  EXPECT_GE(profiles, 2);  // at least the march's first point and a refinement
  EXPECT_EQ(seen.front().phase, "ga");
}

// A start value the fit moved onto its bound, where the model cannot be evaluated: the message
// names the start point and what moved, not the start model file (which evaluates).
TEST(IdentifyProgress, AStartPointMovedOntoABoundThatFailsSaysWhatMoved) {
  const MeasurementSet set = one_record_at(70.0);
  // T_c in [40, 60] degC: the fixture's 400 degC moves onto 60, below the record's 70 degC.
  const FitSpec fit = load_fit_spec("material.Tc_C:40:60");
  const std::string msg =
      input_error([&] { (void)identify(printed_spec(), set, fit, tiny_search()); });
  EXPECT_THAT(msg, HasSubstr("the start point cannot be evaluated"));
  EXPECT_THAT(msg,
              HasSubstr("start value material.Tc_C = 400 lies outside [40, 60]: moved onto the "
                        "bound, the search starts from 60"));
}
