// The request tables (gmasim/experiments/experiment_fields.hpp, issue 21 item 3) and the Metrics
// table: every default satisfies its own row's rule, a value beyond a rule is refused with a
// message naming the option, the report metadata holds each Meta row's value, and every Metrics
// field has a row.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

#include "experiments_fixtures.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
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
    if constexpr (std::is_floating_point_v<T> || std::is_same_v<T, int>) {
      double bad = std::numeric_limits<double>::quiet_NaN();
      switch (row.rule.check) {
        case fields::Check::Any:
          return;
        case fields::Check::Finite:
          if constexpr (std::is_same_v<T, int>) return;  // an int is always finite
          break;
        case fields::Check::Positive:
          bad = 0.0;
          break;
        case fields::Check::NonNegative:
          bad = -1.0;
          break;
        case fields::Check::Range:
          bad = row.rule.hi + std::max(1.0, std::fabs(row.rule.hi));
          if (std::is_same_v<T, int> && bad > 2e9) bad = row.rule.lo - 1.0;
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
