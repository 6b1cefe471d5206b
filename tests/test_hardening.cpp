// Issue 19 ("Hardening II"), the library's side: one test per item, named by the item. The CLI
// side is tests/cli/hardening_cli.sh (ctest cli_hardening), the C API's tests/capi/capi_example.c
// and CApi.FreedAndUnknownHandlesAreErrorCodes, Python's python/tests/test_hardening.py.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "builtin_models.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/validate.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "gmasim/simulate/stepper.hpp"
#include "test_util.hpp"

using gmasim_test::input_error;
using gmasim_test::TempDir;
using ::testing::HasSubstr;
using namespace gmasim;

namespace {

using gmasim_test::mdma;

Model builtin_with(const std::string& key, double value) {
  ModelSpec spec = builtin_model_spec();
  spec.set(key, value);
  return compile(spec);
}

}  // namespace

// ---- item 1 -------------------------------------------------------------------------------
TEST(Hardening, Item1OutputsNeverOverwriteInputs) {
  TempDir dir;
  const std::string in = dir.write("data.csv", "t_s,current_A\n0,1\n1,2\n");
  const std::string other = (dir.path() / "." / "data.csv").string();
  EXPECT_THAT(input_error([&] {
                require_outputs_distinct({{in, "--waveform"}}, {{other, "--out"}});
              }),
              HasSubstr("--out " + other + ": would overwrite the input --waveform " + in));
  std::filesystem::create_symlink(in, dir.path() / "link.csv");
  std::filesystem::create_hard_link(in, dir.path() / "hard.csv");
  for (const char* alias : {"link.csv", "hard.csv"})
    EXPECT_THAT(
        input_error([&] {
          require_outputs_distinct({{in, "--data"}}, {{(dir.path() / alias).string(), "--out"}});
        }),
        HasSubstr("would overwrite the input --data"))
        << alias;
  // A family of outputs (DIR/data*) matches an input it globs; a different name does not.
  EXPECT_THAT(
      input_error([&] {
        require_outputs_distinct({{in, "--model"}}, files_in(dir.path(), {"data*"}, "--out"));
      }),
      HasSubstr("would overwrite the input --model"));
  require_outputs_distinct({{in, "--model"}}, files_in(dir.path(), {"sweep*"}, "--out"));
  // Two outputs of different flags in one file; an allowed pair (resume its own checkpoint).
  const std::string ck = (dir.path() / "ck.txt").string();
  EXPECT_THAT(input_error([&] {
                require_outputs_distinct({}, {{ck, "--out"}, {ck, "--checkpoint"}});
              }),
              HasSubstr("--checkpoint " + ck + ": the same file as --out " + ck));
  require_outputs_distinct({{ck, "--resume"}}, {{ck, "--checkpoint"}},
                           {{"--resume", "--checkpoint"}});
  // An empty output directory is refused, not taken for the current one.
  EXPECT_THAT(input_error([] { ensure_output_dir(""); }), HasSubstr("output directory ''"));
}

// ---- item 2 -------------------------------------------------------------------------------
// At the smallest step the state is held at constant current (the limit keeps a factor 1e8
// from where it is not, near 1e-24 s); a shorter step is refused everywhere.
TEST(Hardening, Item2SmallestStepHoldsTheStateAndShorterIsRefused) {
  auto m = std::make_shared<const Model>(mdma());
  for (double I : {0.0, 5.0}) {
    Stepper st(m, 20.0, kMinStepDt_s, I);
    const double y0 = st.y_m();
    double worst = 0.0;
    for (int k = 0; k < 1000; ++k) worst = std::max(worst, std::fabs(st.step(I) - y0));
    EXPECT_LE(worst, 1e-15) << I << " A: y moved by " << worst << " m";  // observed 0 (1e-20 m)
  }
  EXPECT_THAT(input_error([&] { Stepper(m, 20.0, 1e-28); }),
              HasSubstr("time step dt = 1e-28 s: must be >= 1e-12 s"));
  EXPECT_THAT(input_error([&] { Stepper(m, 20.0, 4.9e-324); }), HasSubstr("must be >= 1e-12 s"));
  EXPECT_THAT(input_error([] { (void)StepGrid::uniform(0.0, 1e-13, 10, "test"); }),
              HasSubstr("test: time step 1e-13 s: must be >= 1e-12 s"));
  SimulationSettings s;
  s.waveform.kind = WaveformKind::DC;
  s.duration_s = 1e-24;
  EXPECT_THAT(input_error([&] { validate(s); }), HasSubstr("shorter than one time step"));
  s.duration_s = 0.01;
  s.dt_s = 1e-28;
  EXPECT_THAT(input_error([&] { validate(s); }), HasSubstr("must be in [1e-12, 0.001] s"));
}

// ---- item 3 -------------------------------------------------------------------------------
TEST(Hardening, Item3GuardEndsPhysicallyImpossibleRuns) {
  SimulationSettings s;
  s.periods = 1;
  const Result r = simulate(builtin_with("material.Es_Pa", 1e3), s);
  ASSERT_TRUE(r.diverged);
  EXPECT_THAT(r.error, HasSubstr("magnetostriction lambda [-]"));
  EXPECT_THAT(r.error, HasSubstr("beyond the physical bound"));
  EXPECT_THAT(r.error, ::testing::ContainsRegex("in rod[123]"));
  EXPECT_THAT(input_error([] { (void)builtin_with("preload.force_N", 1e9); }),
              HasSubstr("beyond the compressive strength of Terfenol-D"));
  // The guard never fires on the built-in model where it is valid: 20-150 degC, 6-12 A p-p,
  // 10-400 Hz (the grid of `model check`).
  const MagneticStateCheck k = check_magnetic_state(mdma());
  EXPECT_EQ(k.divergence, "");
}

TEST(Hardening, Item3ModelWarningsNameTheValue) {
  EXPECT_TRUE(model_warnings(mdma()).empty());
  for (const char* f : {"mdma_printed.toml", "single_rod.toml"})
    EXPECT_TRUE(model_warnings(load_model(std::string(GMASIM_SOURCE_DIR) + "/models/" + f)).empty())
        << f;
  const auto w = model_warnings(builtin_with("material.Es_Pa", 1e3));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_THAT(w[0], ::testing::ContainsRegex("mdma.toml \\(built-in\\):[0-9]+: material.Es_Pa = "
                                             "1000 Pa: far outside Terfenol-D's modulus"));
  // Above 100 MPa in some rod, below the 1 GPa that compile() refuses in every rod.
  const auto p = model_warnings(builtin_with("preload.force_N", 3e4));
  ASSERT_FALSE(p.empty());
  EXPECT_THAT(p[0],
              HasSubstr("preload.force_N = 30000 N: a prestress of up to 596.8 MPa (rod 'rod3')"));
}

// ---- item 4 -------------------------------------------------------------------------------
TEST(Hardening, Item4ThreadCountsAreChecked) {
  SweepRequest r;
  r.temperatures_C = {20};
  r.currents_pp_A = {8};
  r.frequencies_Hz = {100};
  r.periods = 1;
  r.threads = -1;
  EXPECT_THAT(input_error([&] { (void)run_sweep(mdma(), r); }),
              HasSubstr("threads = -1 (--threads): must be 0 (all cores) or in [1, 1024]"));
  IdentifyOptions o;
  o.population = 100000000;
  FitSpec fit;
  fit.parameters.push_back(
      {"material.lambda_s", 0.8e-3, 1.2e-3, ParamScale::Linear, false, 0.0, 1});
  fit.targets.push_back(FitTarget{});
  EXPECT_THAT(input_error([&] { (void)identify(builtin_model_spec(), {}, fit, o); }),
              HasSubstr("--population 100000000: at most 100000"));
  o.population = 24;
  o.islands = 3000;
  EXPECT_THAT(input_error([&] { (void)identify(builtin_model_spec(), {}, fit, o); }),
              HasSubstr("--islands 3000: at most 256 per rank"));
}

// ---- item 5 -------------------------------------------------------------------------------
// Sets written into one directory by several writers at once: the set that stays is one
// writer's (the renames hold the directory's flock); stale temporaries of dead processes go.
TEST(Hardening, Item5ConcurrentSetsStayWholeAndStaleTemporariesGo) {
  TempDir dir;
  const std::string a = (dir.path() / "a.txt").string(), b = (dir.path() / "b.txt").string();
  std::vector<std::thread> writers;
  for (int w = 0; w < 4; ++w)
    writers.emplace_back([&, w] {
      for (int k = 0; k < 50; ++k) {
        const std::string tag = std::to_string(w) + "/" + std::to_string(k);
        write_files_atomic({{a, tag}, {b, tag}});
      }
    });
  for (auto& t : writers) t.join();
  std::ifstream fa(a), fb(b);
  std::string ta, tb;
  std::getline(fa, ta);
  std::getline(fb, tb);
  EXPECT_EQ(ta, tb);
  // A temporary of a process that has ended is removed by the next write of its file.
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  int status = 0;
  ::waitpid(child, &status, 0);
  const std::string stale = a + ".tmp." + std::to_string(child);
  std::ofstream(stale) << "partial";
  write_file_atomic(a, "fresh");
  EXPECT_FALSE(std::filesystem::exists(stale));
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"a.txt", "b.txt"}));
}

// ---- item 6 -------------------------------------------------------------------------------
TEST(Hardening, Item6SynthesizeRefusesWhatIdentifyRefuses) {
  SyntheticRequest r;
  r.objective.steps_per_period = 3;
  EXPECT_THAT(input_error([&] { (void)synthesize_measurements(mdma(), r); }),
              HasSubstr("steps per period 3 (--steps-per-period): must be >= 8"));
  r.objective.steps_per_period = 100;
  r.currents_pp_A = {0.0};
  EXPECT_THAT(input_error([&] { (void)synthesize_measurements(mdma(), r); }),
              HasSubstr("current peak-to-peak 0 A (--currents): must be in (0, 2000] A"));
}

// ---- item 7 -------------------------------------------------------------------------------
TEST(Hardening, Item7MemoryIsEstimatedBeforeTheRun) {
  const auto avail = memory_available();
  ASSERT_TRUE(avail.has_value());
  EXPECT_GT(avail->bytes, 1e6);
  EXPECT_THAT(input_error([] { require_memory(1e30, "a test", "ask for less"); }),
              ::testing::ContainsRegex("a test needs about .* GB of memory; .* are available "
                                       "\\((MemAvailable|RLIMIT_AS).*\\): ask for less"));
  require_memory(1.0, "a byte", "nothing");
}

// ---- item 8 -------------------------------------------------------------------------------
TEST(Hardening, Item8ComputableAndValidatedRanges) {
  const auto c = computable_range(mdma());
  ASSERT_TRUE(c.has_value());
  EXPECT_LT(c->min_C, -50.0);
  EXPECT_GT(c->max_C, 150.0);  // above the validated range (observed 202.8 degC: eq. 3's stress
  EXPECT_LT(c->max_C, 300.0);  // terms exceed 1/chi_m in rod 3 beyond it)
  (void)make_conditions(mdma(), c->max_C);  // the printed bounds are computable
  (void)make_conditions(mdma(), c->min_C);
  const std::string msg = input_error([] { (void)make_conditions(mdma(), 300.0); });
  EXPECT_THAT(msg, HasSubstr("temperature 300 degC: outside the range where models/mdma.toml "
                             "(built-in) can be computed, " +
                             range_text(*c)));
  const TemperatureRange v = validated_range(mdma());
  EXPECT_EQ(v.min_C, 20.0);
  EXPECT_EQ(v.max_C, 150.0);
  EXPECT_FALSE(temperature_warning(mdma(), 100.0).has_value());
  EXPECT_THAT(temperature_warning(mdma(), 250.0).value_or(""),
              HasSubstr("temperature 250 degC: outside the range where models/mdma.toml "
                        "(built-in) was validated, [20, 150] degC"));
  const Model narrow = builtin_with("validity.validated_max_C", 70.0);
  EXPECT_TRUE(temperature_warning(narrow, 100.0).has_value());
  EXPECT_THAT(input_error([] { (void)builtin_with("validity.validated_max_C", 10.0); }),
              HasSubstr("must be > validity.validated_min_C"));
}

// ---- item 11 ------------------------------------------------------------------------------
TEST(Hardening, Item11ThermalExpansionToANegativeLengthIsNamed) {
  EXPECT_THAT(input_error([] {
                (void)make_conditions(builtin_with("material.alpha_thermal_per_K", 0.01), -200.0);
              }),
              HasSubstr("thermal expansion of rod 'rod1' (material.alpha_thermal_per_K = 0.01 "
                        "1/K) makes its length"));
}

TEST(Hardening, Item11WaveformValuesAreShownExactly) {
  Waveform w;
  w.kind = WaveformKind::Table;
  w.table_source = "w.csv";
  w.table_t_s = {0.0, 0.001};
  w.table_current_A = {0.0, 1000.0001};
  EXPECT_THAT(input_error([&] { validate(w); }),
              HasSubstr("w.csv: sample 2 (t = 0.001 s): waveform current = 1000.0001 A"));
}

// A quasi-static record has no time: a divergence names the file, the data row and the drive
// value it was moving to, not "t = 0".
TEST(Hardening, Item11QuasiStaticDivergenceNamesTheRow) {
  ModelSpec spec = load_model_spec(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod.toml");
  spec.set("circuit.branches.coil.coil_turns", 5.0);  // 1000 A x 5 turns: at most ~1e5 A/m
  const Model m = compile(spec);
  Measurement rec;
  rec.path = "loop.csv";
  rec.condition.temperature_C = 20.0;
  rec.condition.quasi_static = true;
  rec.condition.label = "loop";
  rec.drive_kind = DriveInput::Field;
  rec.drive = {0.0, 1e3, 2e3, 5e6, 1e3};  // the 4th field is out of reach
  for (std::size_t k = 0; k < rec.drive.size(); ++k) {
    rec.t_s.push_back(static_cast<double>(k));
    rec.response.push_back(0.0);
  }
  std::vector<double> y;
  try {
    simulate_measurement(m, rec, ObjectiveSettings{}, y);
    ADD_FAILURE() << "no DivergenceError";
  } catch (const DivergenceError& e) {
    EXPECT_THAT(e.what(), HasSubstr("loop.csv: quasi-static record, moving to data row 4 "
                                    "(field_A_per_m = 5e+06, pass 1 of 1)"));
  }
}
