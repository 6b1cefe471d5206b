// Issue 20, "an engineer's first hour": the preload as a prestress in MPa (model key, --set,
// model save, identify condition), the self-heating run's thermal expansion and drift, and
// model save without stale comments.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "model_file_fixture.hpp"
#include "test_util.hpp"

using namespace gmasim;
using namespace gmasim_test;
using ::testing::HasSubstr;
using ::testing::Not;

namespace {

std::string source_path(const std::string& rel) {
  return std::string(GMASIM_SOURCE_DIR) + "/" + rel;
}
std::string template_text() {
  std::ifstream in(source_path("models/single_rod.toml"));
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The 10 mm solid rod of the template: A_1 = pi (5 mm)^2.
constexpr double kTemplateArea_m2 = std::numbers::pi * 0.005 * 0.005;

// A short biased sine of the template at 20 degC: its stroke [um].
double template_stroke(const Model& m) {
  SimulationSettings s;
  s.waveform = biased_sine(6.0, 50.0, 0.0);
  s.periods = 1.0;
  const Result r = simulate(m, s);
  EXPECT_FALSE(r.diverged) << r.error;
  return r.metrics.stroke_um;
}

}  // namespace

// The template gives its preload as a prestress: the force is prestress x A_1 at T_ref, and a
// model given that force instead is the same model (same preload, same run to the bit).
TEST(Prestress, TemplateForceIsPrestressTimesArea) {
  const ModelSpec spec = load_model_spec(source_path("models/single_rod.toml"));
  ASSERT_EQ(spec.params.count("preload.prestress_MPa"), 1u);
  EXPECT_EQ(spec.params.count("preload.force_N"), 0u);
  EXPECT_EQ(preload_key(spec), "preload.prestress_MPa");
  EXPECT_DOUBLE_EQ(preload_area_m2(spec), kTemplateArea_m2);
  const Model m = compile(spec);
  EXPECT_NEAR(m.preload_N, 6.4e6 * kTemplateArea_m2, 1e-12 * m.preload_N);  // 502.65 N
  EXPECT_NEAR(m.preload_N, 502.6548, 1e-3);
  // The stress the conditions use in the rod at T_ref is the prestress given.
  const Conditions c = make_conditions(m, m.T_ref_C);
  EXPECT_NEAR(c.rods[0].sigma_p_Pa, 6.4e6, 6.4e6 * 1e-12);
  // The same preload as a force: the same model.
  const std::string as_force = replace_once(template_text(), "prestress_MPa = 6.4",
                                            fmt::format("force_N = {}", m.preload_N));
  const Model f = compile(parse_model_spec(as_force, "force.toml"));
  EXPECT_EQ(f.preload_N, m.preload_N);
  EXPECT_EQ(template_stroke(f), template_stroke(m));
}

// Both keys, or neither: refused at file:line, naming the keys.
TEST(Prestress, BothOrNeitherKeyIsRefused) {
  const std::string text = template_text();
  const long line = line_of(text, "prestress_MPa = 6.4");
  const std::string both =
      replace_once(text, "prestress_MPa = 6.4", "prestress_MPa = 6.4\nforce_N = 500.0");
  EXPECT_THAT(input_error([&] { (void)parse_model_spec(both, "both.toml"); }),
              HasSubstr(fmt::format("both.toml:{}: [preload]: give preload.force_N or "
                                    "preload.prestress_MPa, not both (lines {} and {})",
                                    line + 1, line, line + 1)));
  const std::string neither = replace_once(text, "prestress_MPa = 6.4", "");
  EXPECT_THAT(input_error([&] { (void)parse_model_spec(neither, "neither.toml"); }),
              HasSubstr("missing key 'force_N' (or 'prestress_MPa') in [preload]"));
  const std::string negative = replace_once(text, "prestress_MPa = 6.4", "prestress_MPa = -2");
  EXPECT_THAT(
      input_error([&] { (void)parse_model_spec(negative, "neg.toml"); }),
      HasSubstr(fmt::format("neg.toml:{}: preload.prestress_MPa = -2 MPa: must be >= 0", line)));
}

// --set preload.prestress_MPa on a model that gives a force replaces it (and back), and the
// saved file holds the key set, on the line of the one it replaced, and loads to the same model.
TEST(Prestress, SetReplacesTheOtherKeyAndSaves) {
  ModelSpec spec = builtin_model_spec();
  const double A1 = preload_area_m2(spec);  // rod1 of the MDMA
  const double F0 = spec.get("preload.force_N");
  spec.set("preload.prestress_MPa", 10.0);
  EXPECT_EQ(spec.params.count("preload.force_N"), 0u);
  const Model m = compile(spec);
  EXPECT_NEAR(m.preload_N, 10e6 * A1, 1e-9);
  EXPECT_THAT(input_error([&] { spec.set("preload.prestress_MPa", -1.0); }),
              HasSubstr("preload.prestress_MPa = -1 MPa: must be >= 0"));
  const std::string text = model_toml(spec, "test");
  const std::string was = "prestress_MPa = 10.0  # set: test; was force_N = ";
  const auto at = text.find(was);
  ASSERT_NE(at, std::string::npos) << text;
  EXPECT_NEAR(std::stod(text.substr(at + was.size())), F0, 1e-9 * F0);  // the replaced force
  const ModelSpec back = parse_model_spec(text, "back.toml");
  EXPECT_EQ(back.get("preload.prestress_MPa"), 10.0);
  EXPECT_EQ(compile(back).preload_N, m.preload_N);
  spec.set("preload.force_N", 700.0);  // and back to a force
  EXPECT_EQ(compile(spec).preload_N, 700.0);
  EXPECT_EQ(spec.params.count("preload.prestress_MPa"), 0u);
}

// model save replaces a changed value's comment: the old one described the old value
// ("3.6 / 5.5 / 9.9 MPa in rods 1 / 2 / 3" is wrong for 800 N).
TEST(Prestress, SaveDropsTheStaleComment) {
  ModelSpec spec = load_model_spec(source_path("models/mdma_printed.toml"));
  spec.set("preload.force_N", 800.0);
  const std::string text = model_toml(spec, "test");
  const auto at = text.find("force_N = 800.0");
  ASSERT_NE(at, std::string::npos);
  const std::string line = text.substr(at, text.find('\n', at) - at);
  EXPECT_EQ(line, "force_N = 800.0  # set: test; was 500.0");
  EXPECT_THAT(line, Not(HasSubstr("MPa")));
}

// The identify condition prestress_MPa: a record measured at 10 MPa is simulated with the
// preload that gives the first rod 10 MPa, whatever the model's own preload.
TEST(Prestress, IdentifyConditionSetsTheRecordsPreload) {
  TempDir dir;
  std::string csv = "# temperature_C = 20\n# prestress_MPa = 10\nt_s,current_A,displacement_um\n";
  for (int k = 0; k <= 200; ++k) {
    const double t = k * 1e-4;
    csv += fmt::format("{},{},0\n", t, 3.0 - 3.0 * std::cos(2.0 * std::numbers::pi * 50.0 * t));
  }
  const Measurement rec = load_measurement_csv(dir.write("r.csv", csv));
  EXPECT_EQ(rec.condition.prestress_MPa, 10.0);
  const Model base = load_model(source_path("models/single_rod.toml"));  // 6.4 MPa
  ModelSpec at10 = base.spec;
  at10.set("preload.prestress_MPa", 10.0);
  const Model m10 = compile(at10);
  ObjectiveSettings s;
  std::vector<double> y_cond, y_model, y_base;
  simulate_measurement(base, rec, s, y_cond);
  Measurement plain = rec;
  plain.condition.prestress_MPa = std::nan("");
  simulate_measurement(m10, plain, s, y_model);
  simulate_measurement(base, plain, s, y_base);
  EXPECT_EQ(y_cond, y_model);  // the condition's preload, to the bit
  EXPECT_NE(y_cond, y_base);   // and not the model's own
  const std::string bad = replace_once(csv, "prestress_MPa = 10", "prestress_MPa = -3");
  EXPECT_THAT(input_error([&] { (void)load_measurement_csv(dir.write("bad.csv", bad)); }),
              HasSubstr("bad.csv:2: prestress_MPa = -3: must be in [0, 1000] MPa"));
}

// Self-heating: the thermal expansion reported is the one at the end of the run (the last
// xT_um), not the start's 0 at T_ref; the start is reported beside it.
TEST(SelfHeatingReport, ThermalExpansionIsTheEndValue) {
  const Model m = compile(builtin_model_spec());
  SimulationSettings s;
  s.waveform = biased_sine(12.0, 10.0, -6.0);
  s.periods = 10.0;
  s.record_every = 10;
  s.self_heating.enabled = true;
  s.self_heating.thermal_step_s = 0.1;
  const Result r = simulate(m, s);
  ASSERT_FALSE(r.diverged) << r.error;
  EXPECT_EQ(r.thermal_expansion_start_um, 0.0);  // at T_ref = 20 degC
  const auto& xT = r.series.column("xT_um");
  EXPECT_EQ(r.thermal_expansion_um, xT.back());
  EXPECT_GT(r.thermal_expansion_um, 1e-4);  // the rods warmed
  // self_heating.csv holds the drift per thermal step: x_T over the last step is the end value
  const auto& hx = r.heating.column("xT_um");
  EXPECT_EQ(hx.front(), 0.0);
  EXPECT_EQ(hx.back(), r.thermal_expansion_um);
  for (std::size_t k = 1; k < hx.size(); ++k) EXPECT_GE(hx[k], hx[k - 1]);  // heating only
  EXPECT_EQ(r.heating.column("y_mean_um").size(), hx.size());
  const std::string json = metrics_json(r, s, m, "");
  const auto key = json.find("\"thermal_expansion_um\": ");
  ASSERT_NE(key, std::string::npos);
  EXPECT_NEAR(std::stod(json.substr(key + 23)), xT.back(), 1e-12 * std::fabs(xT.back()));
  EXPECT_THAT(json, HasSubstr("\"thermal_expansion_start_um\": 0"));
  EXPECT_THAT(json, HasSubstr("\"thermal_drift_over_run_um\""));
}
