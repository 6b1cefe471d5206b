// The request tables (gmasim/experiments/experiment_fields.hpp, issue 21 item 3) and the Metrics
// table: every default satisfies its own row's rule, a value beyond a rule is refused with a
// message naming the option, the report metadata holds each Meta row's value, and every Metrics
// field has a row.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "experiments_fixtures.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/simulate_fields.hpp"
#include "gmasim/identify/synthetic_fields.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {
namespace {

// For each scalar row with a bound: the value just outside it (a NaN for Finite) must throw an
// InputError that names the row's option (or its name when it has none).
template <class R>
int check_rows_refuse_out_of_rule() {
  int checked = 0;
  fields::for_each_field<R>([&](const auto& row) {
    using T = typename std::remove_cvref_t<decltype(row)>::Value;
    if constexpr (std::is_floating_point_v<T> || std::is_same_v<T, int> ||
                  std::is_same_v<T, long>) {
      double bad = std::numeric_limits<double>::quiet_NaN();
      switch (row.rule.check) {
        case fields::Check::Any:
          return;
        case fields::Check::Finite:
          if constexpr (!std::is_floating_point_v<T>) return;  // an integer is always finite
          break;
        case fields::Check::Positive:
          bad = 0.0;
          break;
        case fields::Check::NonNegative:
          bad = -1.0;
          break;
        case fields::Check::Range:
          bad = row.rule.hi + std::max(1.0, std::fabs(row.rule.hi));
          if (!std::is_floating_point_v<T> && bad > 2e9) bad = row.rule.lo - 1.0;
          break;
      }
      R r{};
      row.ref(r) = static_cast<T>(bad);
      const std::string who(row.cli.empty() ? row.name : row.cli);
      try {
        fields::check_request_fields(r);
        ADD_FAILURE() << who << " = " << bad << " was accepted";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(who), std::string::npos) << e.what();
      }
      ++checked;
    }
  });
  return checked;
}

template <class R>
void check_table() {
  EXPECT_NO_THROW(fields::check_request_fields(R{})) << fields::RequestFields<R>::experiment;
  EXPECT_GT(check_rows_refuse_out_of_rule<R>(), 2) << fields::RequestFields<R>::experiment;
}

TEST(RequestTables, DefaultsPassTheirRulesAndValuesBeyondARuleAreRefused) {
  check_table<SweepRequest>();
  check_table<FrfRequest>();
  check_table<TrackRequest>();
  check_table<AblateRequest>();
  check_table<ParamsVsTemperatureRequest>();
  check_table<CompensateRequest>();
  check_table<SensitivitySettings>();
  check_table<FeedforwardEvaluationRequest>();
  check_table<SyntheticRequest>();
  check_table<SimulateOptions>();
}

// The library's own checks keep their messages; the tables' rules are no stricter, so every
// default passes both and a value the rule refuses is refused by the run too (synthesize: its
// own check or the table's, either naming the option).
TEST(RequestTables, SyntheticRequestBeyondItsRulesIsRefusedBeforeAnyWork) {
  const Model& m = gmasim_experiments_test::mdma();
  auto refused = [&](SyntheticRequest r, const std::string& option) {
    try {
      (void)synthesize_measurements(m, r);
      ADD_FAILURE() << option << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(option), std::string::npos) << e.what();
    }
  };
  SyntheticRequest r;
  r.samples_per_period = 4;
  refused(r, "--samples-per-period");
  r = {};
  r.objective.dt_s = 2e-3;  // above kMaxStepDt_s: validate(ObjectiveSettings) names --dt
  refused(r, "--dt");
  r = {};
  r.currents_pp_A = {6.0, 2.0 * kMaxCurrent_A + 1.0};
  refused(r, "--currents");
}

TEST(RequestTables, FeedforwardReportMetadataIsItsTablesRows) {
  const Model& m = gmasim_experiments_test::mdma();
  FeedforwardEvaluationRequest req;
  req.track.gains.kp = 0.125;
  req.track.gains.ki = 0.0625;
  req.track.sample_rate_Hz = 25000.0;
  req.track.periods = 3.0;
  req.track.inverse.band_Hz = 750.0;
  req.track.inverse.dynamic = false;
  req.schedule_frequency_Hz = 12.5;
  const Report r = feedforward_report(m, req, FeedforwardEvaluation{});
  std::vector<std::string> keys;
  for (const auto& [k, v] : r.meta) keys.push_back(k);
  // The order of the file before the table: model, feedforward, the rows, then the texts.
  const std::vector<std::string> want = {"model",
                                         "feedforward",
                                         "kp_A_per_um",
                                         "ki_A_per_um_per_sample_at_reference_rate",
                                         "kd_A_per_um_per_sample_at_reference_rate",
                                         "sample_rate_Hz",
                                         "bias_A",
                                         "current_limit_A",
                                         "amplifier_A_per_unit",
                                         "periods",
                                         "inverse_band_Hz",
                                         "inverse_dynamic",
                                         "schedule_frequency_Hz",
                                         "mismatch",
                                         "goal",
                                         "threads",
                                         "wall_time_s"};
  EXPECT_EQ(keys, want);
  auto meta = [&](const std::string& key) -> const Cell& {
    return r.meta[static_cast<std::size_t>(std::find(keys.begin(), keys.end(), key) - keys.begin())]
        .second;
  };
  EXPECT_EQ(meta("kp_A_per_um").number, 0.125);
  EXPECT_EQ(meta("ki_A_per_um_per_sample_at_reference_rate").number, 0.0625);
  EXPECT_EQ(meta("kd_A_per_um_per_sample_at_reference_rate").number, req.track.gains.kd);
  EXPECT_EQ(meta("sample_rate_Hz").number, 25000.0);
  EXPECT_EQ(meta("bias_A").number, TrackRequest{}.bias_A);
  EXPECT_EQ(meta("periods").number, 3.0);
  EXPECT_EQ(meta("inverse_band_Hz").number, 750.0);
  EXPECT_TRUE(meta("inverse_dynamic").is_bool);
  EXPECT_EQ(meta("inverse_dynamic").text, "false");
  EXPECT_EQ(meta("schedule_frequency_Hz").number, 12.5);
}

TEST(RequestTables, SensitivityJsonSettingsAreItsTablesMetaRows) {
  SensitivityResult res;
  res.settings.step_large = 0.03125;
  res.settings.step_small = 0.0078125;
  res.settings.agreement = 0.25;
  res.settings.floor_fraction = 0.5;
  res.settings.quick = true;
  res.settings.near_null_ratio = 0.125;  // not a Meta row: not in the settings
  const std::string j = sensitivity_json(res, "m");
  const std::size_t steps = j.find("\"steps\": {\"large\": 0.03125, \"small\": 0.0078125}");
  const std::size_t agreement = j.find("\"agreement\": 0.25");
  const std::size_t floor = j.find("\"floor_fraction\": 0.5");
  const std::size_t quick = j.find("\"quick\": true");
  ASSERT_NE(steps, std::string::npos) << j.substr(0, 400);
  ASSERT_NE(agreement, std::string::npos) << j.substr(0, 400);
  ASSERT_NE(floor, std::string::npos) << j.substr(0, 400);
  ASSERT_NE(quick, std::string::npos) << j.substr(0, 400);
  EXPECT_LT(steps, agreement);  // the table's order
  EXPECT_LT(agreement, floor);
  EXPECT_LT(floor, quick);
  EXPECT_EQ(j.find("0.125"), std::string::npos);
}

TEST(RequestTables, ReportMetadataHoldsTheMetaRowsValues) {
  const Model& m = gmasim_experiments_test::mdma();
  AblateRequest req;
  req.temperature_C = 42.5;
  req.current_pp_A = 7.25;
  req.periods = 2.0;
  const Report r = ablate_report(m, req, AblateResult{});
  auto meta = [&](const std::string& key) {
    for (const auto& [k, v] : r.meta)
      if (k == key) return v.number;
    ADD_FAILURE() << key << " missing";
    return std::nan("");
  };
  EXPECT_EQ(meta("temperature_C"), 42.5);
  EXPECT_EQ(meta("current_pp_A"), 7.25);
  EXPECT_EQ(meta("current_min_A"), req.current_min_A);
  EXPECT_EQ(meta("periods"), 2.0);
}

TEST(MetricsTable, EveryFieldHasOneRow) {
  static_assert(sizeof(Metrics) == std::size(kMetricRows) * sizeof(double));
  Metrics m;
  double v = 1.0;
  for (const MetricRow& row : kMetricRows) m.*row.member = (v *= 2.0);
  // Distinct members: every row wrote its own field (a repeated member would leave one at 0).
  for (double x :
       {m.window_start_s, m.window_end_s, m.stroke_um, m.hysteresis_um, m.B_pp_T, m.y_mean_um})
    EXPECT_GT(x, 1.0);
}

}  // namespace
}  // namespace gmasim
