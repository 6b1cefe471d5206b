// Input and output: waveform CSV, output files (atomic writes, metrics.json), error
// messages, the validation layer, input-size limits.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/validate.hpp"
#include "model_file_fixture.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;
using namespace gmasim_test;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

// =======================================================================================
// Waveform CSV
// =======================================================================================
TEST(WaveformCsv, Loads) {
  TempDir dir;
  const auto path = dir.write("w.csv", "t_s,current_A\r\n0,0\r\n0.001, 1.5\r\n0.002,-2e-1\r\n");
  const auto w = gmasim::load_waveform_csv(path);
  EXPECT_EQ(w.kind, gmasim::WaveformKind::Table);
  EXPECT_EQ(w.table_source, path);
  EXPECT_EQ(w.table_t_s, (std::vector<double>{0.0, 0.001, 0.002}));
  EXPECT_EQ(w.table_current_A, (std::vector<double>{0.0, 1.5, -0.2}));
}

TEST(WaveformCsv, MissingFile) {
  TempDir dir;
  const auto path = (dir.path() / "none.csv").string();
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ": cannot open waveform file (No such file or directory)");
}

TEST(WaveformCsv, EmptyFile) {
  TempDir dir;
  const auto path = dir.write("e.csv", "");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }), path + ":1: empty file");
}

TEST(WaveformCsv, BadHeader) {
  TempDir dir;
  const auto path = dir.write("h.csv", "time,current\n0,1\n1,2\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":1: expected header 't_s,current_A', got 'time,current'");
}

TEST(WaveformCsv, NonNumericCell) {
  TempDir dir;
  const auto path = dir.write("n.csv", "t_s,current_A\n0,1\n0.001,abc\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":3: non-numeric cell 'abc' in column current_A");
}

TEST(WaveformCsv, WrongCellCount) {
  TempDir dir;
  const auto path = dir.write("c.csv", "t_s,current_A\n0,1,2\n0.001,1\n");
  EXPECT_THAT(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
              StartsWith(path + ":2: expected 2 cells"));
}

TEST(WaveformCsv, TimeDoesNotIncrease) {
  TempDir dir;
  const auto path = dir.write("t.csv", "t_s,current_A\n0.001,0\n0.003,1\n0.002,2\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":4: time 0.002 s does not increase (previous 0.003 s)");
}

TEST(WaveformCsv, RepeatedTime) {
  TempDir dir;
  const auto path = dir.write("r.csv", "t_s,current_A\n0,0\n0,1\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":3: time 0 s does not increase (previous 0 s)");
}

TEST(WaveformCsv, NaN) {
  TempDir dir;
  const auto path = dir.write("nan.csv", "t_s,current_A\n0,0\n0.001,nan\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":3: NaN in column current_A ('nan')");
}

TEST(WaveformCsv, Inf) {
  TempDir dir;
  const auto path = dir.write("inf.csv", "t_s,current_A\n0,0\ninf,1\n");
  EXPECT_EQ(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
            path + ":3: Inf in column t_s ('inf')");
}

TEST(WaveformCsv, FewerThanTwoRows) {
  TempDir dir;
  const auto path = dir.write("one.csv", "t_s,current_A\n0,1\n");
  EXPECT_THAT(input_error([&] { (void)gmasim::load_waveform_csv(path); }),
              StartsWith(path + ":2: needs at least 2 data rows, found 1"));
}

// =======================================================================================
// Output files
// =======================================================================================
TEST(Output, AtomicWriteLeavesNoTempFiles) {
  TempDir dir;
  const auto path = (dir.path() / "out.csv").string();
  gmasim::write_file_atomic(path, "first\n");
  gmasim::write_file_atomic(path, "second\n");
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "second\n");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"out.csv"}));
}

TEST(Output, AtomicWriteFailureNamesPathAndLeavesNothing) {
  TempDir dir;
  const auto path = (dir.path() / "missing_dir" / "out.csv").string();
  EXPECT_EQ(input_error([&] { gmasim::write_file_atomic(path, "x"); }),
            path + ": cannot write output (No such file or directory)");
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Output, EnsureOutputDirCreatesParents) {
  TempDir dir;
  const auto sub = (dir.path() / "a" / "b").string();
  gmasim::ensure_output_dir(sub);
  EXPECT_TRUE(fs::is_directory(sub));
  EXPECT_TRUE(fs::is_empty(sub));  // the writability probe is removed
}

TEST(Output, OutputDirNotWritable) {
  // Tests may run as root, so permissions cannot make a directory unwritable: use a
  // regular file as the parent.
  TempDir dir;
  const auto file = dir.write("plain_file", "x");
  const auto sub = file + "/sub";
  const auto msg = input_error([&] { gmasim::ensure_output_dir(sub); });
  EXPECT_THAT(msg, StartsWith(sub + ": output directory is not writable ("));
  EXPECT_THAT(msg, HasSubstr("Not a directory"));
}

TEST(Output, OutputDirIsARegularFile) {
  TempDir dir;
  const auto file = dir.write("plain_file", "x");
  EXPECT_THAT(input_error([&] { gmasim::ensure_output_dir(file); }),
              StartsWith(file + ": output directory is not writable ("));
}

TEST(Output, TimeseriesCsv) {
  gmasim::TimeSeries ts;
  ts.names = {"t_s", "y_um"};
  ts.columns = {{0.0, 1e-5}, {1.0 / 3.0, -2.5}};
  EXPECT_EQ(gmasim::timeseries_csv(ts), "t_s,y_um\n0,0.3333333333\n1e-05,-2.5\n");
}

TEST(Output, MetricsJson) {
  gmasim::Result r;
  r.dt_s = 5e-6;
  r.steps = 60000;
  r.wall_time_s = 0.25;
  r.has_metrics = true;
  r.metrics.stroke_um = 12.5;
  r.metrics.hysteresis_um = std::nan("");
  r.thermal_expansion_um = 0.0;
  r.quantities.push_back({"rod1_F_N", 3.0, 4.5, 9.0, -0.25});
  gmasim::SimulationSettings s;
  s.waveform = gmasim::Waveform{};
  gmasim::Model m;
  m.spec.source = "dir\\model \"x\".toml";
  const auto json = gmasim::metrics_json(r, s, m);
  EXPECT_THAT(json, HasSubstr("\"status\": \"ok\""));
  EXPECT_THAT(json, HasSubstr("\"error\": null"));
  EXPECT_THAT(json, HasSubstr("\"model\": \"dir\\\\model \\\"x\\\".toml\""));
  EXPECT_THAT(json, HasSubstr("\"kind\": \"biased_sine\""));
  EXPECT_THAT(json, HasSubstr("\"pp_A\": 8"));
  EXPECT_THAT(json, HasSubstr("\"dt_s\": 5e-06"));
  EXPECT_THAT(json, HasSubstr("\"steps\": 60000"));
  EXPECT_THAT(json, HasSubstr("\"stroke_um\": 12.5"));
  EXPECT_THAT(json, HasSubstr("\"hysteresis_um\": null"));  // JSON has no NaN
  EXPECT_THAT(json, HasSubstr("\"thermal_expansion_um\": 0"));
  EXPECT_THAT(json, HasSubstr("\"rod1_F_N\": {\n      \"rms\": 3,\n      \"peak\": 4.5"));

  r.diverged = true;
  r.has_metrics = false;
  r.error = "diverged at t = 0.1 s in rod1: H = inf (line\n2)";
  const auto bad = gmasim::metrics_json(r, s, m);
  EXPECT_THAT(bad, HasSubstr("\"status\": \"diverged\""));
  EXPECT_THAT(bad, HasSubstr("\"error\": \"diverged at t = 0.1 s in rod1: H = inf (line\\n2)\""));
  EXPECT_THAT(bad, Not(HasSubstr("\"metrics\"")));
}

// =======================================================================================
// Error helpers
// =======================================================================================
TEST(Errors, Located) {
  EXPECT_EQ(gmasim::located("m.toml", 12, "bad"), "m.toml:12: bad");
  EXPECT_EQ(gmasim::located("m.toml", 0, "bad"), "m.toml: bad");
}

TEST(Errors, DivergenceMessage) {
  const gmasim::DivergenceError e(0.0125, "rod2", "M_A_per_m", INFINITY, "not finite");
  EXPECT_STREQ(e.what(), "diverged at t = 0.012500000 s in rod2: M_A_per_m = inf (not finite)");
  EXPECT_EQ(e.rod, "rod2");
  EXPECT_EQ(e.time_s, 0.0125);
  const gmasim::DivergenceError f(1.5, "", "B_T", 7.0, "circuit matrix not positive definite");
  EXPECT_STREQ(f.what(),
               "diverged at t = 1.500000000 s: B_T = 7 (circuit matrix not positive definite)");
}

// ---------------------------------------------------------------------------------------
// The validation layer (gmasim/model/validate.hpp, issue 8)
// ---------------------------------------------------------------------------------------
TEST(Validate, CountsAreCheckedBeforeConversion) {
  using gmasim::checked_count;
  EXPECT_EQ(checked_count(3.4, 10, "n"), 3);
  EXPECT_EQ(checked_count(10.0, 10, "n"), 10);
  EXPECT_EQ(gmasim::checked_ceil_count(2.0000000001, 10, "n"), 2);  // 1e-9 slack
  EXPECT_EQ(gmasim::checked_ceil_count(2.01, 10, "n"), 3);
  EXPECT_EQ(input_error([] { checked_count(1e300, 1e6, "steps"); }),
            "steps = 1e+300: too many (limit 1e+06)");
  EXPECT_EQ(input_error([] { checked_count(-1.0, 1e6, "steps"); }), "steps = -1: must be >= 0");
  EXPECT_EQ(input_error([] { checked_count(std::nan(""), 1e6, "steps"); }),
            "steps = nan: not a finite count");
  EXPECT_EQ(input_error([] { checked_count(INFINITY, 1e6, "steps"); }),
            "steps = inf: not a finite count");
  EXPECT_EQ(input_error([] { gmasim::checked_ceil_count(INFINITY, 1e6, "n"); }),
            "n = inf: not a finite count");
  EXPECT_THAT(input_error([] { gmasim::checked_step_count(1e300, 1e-5, "run"); }),
              HasSubstr("too many (limit 2e+08)"));
  EXPECT_EQ(gmasim::checked_step_count(0.1, 1e-5, "run"), 10000);
}

TEST(Validate, RangesNameTheValueTheUnitAndTheRule) {
  EXPECT_EQ(input_error([] { gmasim::require_in(5.0, 0.0, 1.0, "x", "A"); }),
            "x = 5 A: must be in [0 A, 1 A]");
  EXPECT_EQ(input_error([] { gmasim::require_positive(0.0, "f", "Hz"); }), "f = 0 Hz: must be > 0");
  EXPECT_EQ(input_error([] { gmasim::require_finite(-INFINITY, "T", "degC"); }),
            "T = -inf degC: must be a finite number");
  EXPECT_EQ(input_error([] { gmasim::require_int_in(0, 1, 9, "islands"); }),
            "islands = 0: must be in [1, 9]");
}

TEST(Validate, LongMessagesAreClipped) {
  const std::string line(1'000'000, 'x');
  const gmasim::InputError e("bad value '" + line + "'");
  EXPECT_LE(std::string(e.what()).size(), gmasim::kMaxErrorChars + 100);
  EXPECT_THAT(e.what(), HasSubstr("characters omitted"));
  EXPECT_THAT(e.what(), StartsWith("bad value 'xxx"));
  EXPECT_EQ(gmasim::clip_for_message("short"), "short");
}

TEST(Validate, SimulationSettingsAreRefusedBeforeAnyWork) {
  const gmasim::Model m = gmasim::compile(fixture_spec());
  auto err = [&](auto edit) {
    gmasim::SimulationSettings s;
    edit(s);
    return input_error([&] { (void)gmasim::simulate(m, s); });
  };
  using S = gmasim::SimulationSettings;
  EXPECT_EQ(err([](S& s) { s.periods = 1e300; }),
            "periods (--periods) = 1e+300: must be in [1, 1e+06]");
  EXPECT_THAT(err([](S& s) { s.waveform.frequency_Hz = 1e-300; }), HasSubstr("too many"));
  // Issue 19, item 2: below the smallest step, before it becomes a count.
  EXPECT_THAT(err([](S& s) { s.dt_s = 1e-300; }), HasSubstr("must be in [1e-12, 0.001] s"));
  EXPECT_THAT(err([](S& s) { s.periods = 3000; }), HasSubstr("record less often"));
  EXPECT_EQ(err([](S& s) { s.temperature_C = std::nan(""); }),
            "temperature = nan degC: must be a finite number");
  EXPECT_EQ(err([](S& s) { s.duration_s = INFINITY; }),
            "duration = inf s: must be a finite number");
  EXPECT_EQ(err([](S& s) {
              s.waveform.kind = gmasim::WaveformKind::Step;
              s.waveform.step_time_s = std::nan("");
              s.duration_s = 0.01;
            }),
            "step time = nan s: must be a finite number");
  for (const double t :
       {0.0, -1.0, 0.01, 1e308})  // no step inside the run: refused, not a 0 stroke
    EXPECT_THAT(err([t](S& s) {
                  s.waveform.kind = gmasim::WaveformKind::Step;
                  s.waveform.step_to_A = 1.0;
                  s.waveform.step_time_s = t;
                  s.duration_s = 0.01;
                }),
                HasSubstr("(--step-time): must be inside the run, 0 < t < 0.01 s"))
        << t;
  // the chirp's extremes, not only its offset and amplitude
  EXPECT_THAT(err([](S& s) {
                s.waveform.kind = gmasim::WaveformKind::Chirp;
                s.waveform.offset_A = 900.0;
                s.waveform.amplitude_A = 900.0;
                s.duration_s = 0.01;
              }),
              HasSubstr("chirp maximum (offset + amplitude) = 1800 A"));
  EXPECT_EQ(err([](S& s) {
              s.waveform.kind = gmasim::WaveformKind::Table;
              s.waveform.table_t_s = {100.0, 100.01};
              s.waveform.table_current_A = {1.0, 2.0};
            }),
            "waveform table: starts at t = 100 s; a waveform table must start at t = 0 (the "
            "run starts there): subtract 100 s from t_s");
  // 3000 periods recorded every 10th step are fine to validate (not run here).
  gmasim::SimulationSettings ok;
  ok.periods = 3000;
  ok.record_every = 10;
  EXPECT_NO_THROW(gmasim::validate(ok));
}

TEST(Output, NeverReplacesANonRegularFile) {
  TempDir dir;
  const auto link = dir.path() / "metrics.json";
  fs::create_symlink("/dev/null", link);
  EXPECT_THAT(input_error([&] { gmasim::write_file_atomic(link.string(), "x"); }),
              HasSubstr("the destination is a character device"));
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  fs::create_directory(dir.path() / "sub");
  EXPECT_THAT(input_error([&] { gmasim::write_file_atomic((dir.path() / "sub").string(), "x"); }),
              HasSubstr("the destination is a directory"));
}

TEST(Output, WriteFilesAtomicWritesAllOrNothing) {
  TempDir dir;
  const auto a = (dir.path() / "a.csv").string(), b = (dir.path() / "b.json").string();
  gmasim::write_files_atomic({{a, "A1"}, {b, "B1"}});
  // The second destination is refused: neither file changes, no temporary is left.
  fs::create_directory(dir.path() / "c");
  const auto c = (dir.path() / "c").string();
  EXPECT_THROW(gmasim::write_files_atomic({{a, "A2"}, {c, "C2"}}), gmasim::InputError);
  std::ifstream in(a);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "A1");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"a.csv", "b.json", "c"}));
}

TEST(Input, FilesLargerThanTheLimitAreRefused) {
  TempDir dir;
  const auto big = (dir.path() / "big.toml").string();
  {
    std::ofstream out(big);  // a sparse file just over the limit
  }
  fs::resize_file(big, gmasim::kMaxInputBytes + 1);
  EXPECT_THAT(input_error([&] { (void)gmasim::read_input_file(big, "model file"); }),
              HasSubstr("model file is larger than 256 MiB"));
}

TEST(Input, TomlGuardRefusesWhatTomlPlusPlusMishandles) {
  for (const char* text : {"[[[1]]]\n", "[[[a]]\n", "[[[]]\n", "[[=\n", "[&\n", "[\xCE\xA0]\n"})
    EXPECT_THAT(input_error([&] { (void)gmasim::parse_model_spec(text, "t.toml"); }),
                StartsWith("t.toml:1: malformed table header"))
        << text;
  EXPECT_THAT(input_error([] { (void)gmasim::parse_model_spec("\xCE\xA0 = 1\n", "t.toml"); }),
              StartsWith("t.toml:1: expected a key"));
  EXPECT_THAT(
      input_error([] { (void)gmasim::parse_model_spec(std::string("a = 1\n\0", 7), "t.toml"); }),
      StartsWith("t.toml:2: NUL byte"));
  // Brackets inside strings, comments and multi-line arrays are values, not headers.
  const std::string fine =
      "\xEF\xBB\xBF# [&\n[meta]\nname = \"[[=\"  # ]\nlist = [\n  [1, 2],\n  [\n  3],\n]\n"
      "s = '''\n[&\n'''\n";
  const std::string err = input_error([&] { (void)gmasim::parse_model_spec(fine, "t.toml"); });
  EXPECT_THAT(err, Not(HasSubstr("malformed")));
  EXPECT_THAT(err, Not(HasSubstr("expected a key")));
}