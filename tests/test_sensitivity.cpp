// gmasim sensitivity (gmasim/experiments/sensitivity.hpp): the claims from only the experiments
// they need (the same numbers as the whole study), central differences against analytic
// derivatives, the two step sizes, the flags, thread-count independence, identifiability.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "experiments_fixtures.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/reproduce.hpp"
#include "gmasim/experiments/sensitivity.hpp"
#include "gmasim/io/io.hpp"

namespace {

using gmasim_experiments_test::input_error_of;
using gmasim_experiments_test::mdma;
using namespace gmasim;

// Only the quantities named, no metric quantities unless named.
SensitivityRequest request(std::vector<std::string> params, std::vector<std::string> only) {
  SensitivityRequest r;
  for (auto& p : params) r.parameters.push_back({std::move(p), 0.0});
  r.only = std::move(only);
  r.threads = 2;
  return r;
}

std::size_t index_of(const SensitivityResult& r, const std::string& param) {
  for (std::size_t j = 0; j < r.parameters.size(); ++j)
    if (r.parameters[j].name == param) return j;
  ADD_FAILURE() << "no parameter " << param;
  return 0;
}

// Every claim of the built-in data, from only the parts of the study it needs, is the number
// of the whole study (quick grids: the claims' points are on them), and so is pass/fail.
TEST(RunClaims, MatchesTheFullStudy) {
  ReproduceOptions o;
  o.quick = true;
  const ReproduceResult full = run_reproduce(mdma(), o);
  const std::vector<Claim> part = run_claims(mdma(), o);
  ASSERT_EQ(part.size(), full.claims.size());
  int finite = 0;
  for (std::size_t k = 0; k < part.size(); ++k) {
    const Claim &a = part[k], &b = full.claims[k];
    ASSERT_EQ(a.id, b.id);
    EXPECT_EQ(a.applicable, b.applicable) << a.id;
    EXPECT_EQ(a.pass, b.pass) << a.id;
    if (std::isnan(b.ours)) {
      EXPECT_TRUE(std::isnan(a.ours)) << a.id;
    } else {
      EXPECT_EQ(a.ours, b.ours) << a.id;  // the same runs: the same bits
      ++finite;
    }
  }
  EXPECT_GE(finite, 30);
  // A subset runs less and gives the same numbers.
  const std::vector<Claim> two = run_claims(mdma(), o, {"thermal_model", "stroke_drop_8A"});
  ASSERT_EQ(two.size(), 2u);
  for (const auto& c : two)
    for (const auto& b : full.claims)
      if (b.id == c.id) {
        EXPECT_EQ(c.ours, b.ours) << c.id;
      }
  EXPECT_NE(input_error_of([&] { run_claims(mdma(), o, {"nope"}); }).find("unknown claim 'nope'"),
            std::string::npos);
}

// Eq. 21 is linear in every length and expansion coefficient: x_T' = 1e6 (alpha_r l_r +
// alpha_m l_m + alpha_o l_o - alpha_s l_s) um/degC. Central differences of a linear function
// are exact, so d x_T'/d l_s = -1e6 alpha_s to rounding. Scaling identities: the sleeve's
// length and coefficient enter as a product (equal derivatives per unit relative change), and
// x_T' is homogeneous of degree 1 in the coefficients (Euler: the sum of d/d ln alpha is x_T').
TEST(Sensitivity, ThermalClaimMatchesEq21) {
  SensitivityRequest r =
      request({"thermal_expansion.sleeve_length_m", "thermal_expansion.sleeve_alpha_per_K",
               "material.alpha_thermal_per_K", "thermal_expansion.magnetizer_alpha_per_K",
               "thermal_expansion.output_rod_alpha_per_K"},
              {"thermal_model"});
  const SensitivityResult s = run_sensitivity(mdma(), r);
  ASSERT_EQ(s.quantities.size(), 1u);
  const auto& row = s.entries[0];
  const double q = s.quantities[0].value;
  EXPECT_NEAR(q, 0.662, 5e-4);
  const ModelSpec& spec = mdma().spec;
  const double a_s = spec.get("thermal_expansion.sleeve_alpha_per_K");
  const double l_s = spec.get("thermal_expansion.sleeve_length_m");
  for (const auto& p : s.parameters) EXPECT_EQ(p.step, StepKind::Absolute) << p.name;  // >= 0
  const auto& ls = row[index_of(s, "thermal_expansion.sleeve_length_m")];
  const auto& as = row[index_of(s, "thermal_expansion.sleeve_alpha_per_K")];
  EXPECT_NEAR(ls.derivative_large, -1e6 * a_s, 1e-9 * 1e6 * a_s);
  EXPECT_NEAR(ls.derivative_small, -1e6 * a_s, 1e-9 * 1e6 * a_s);
  EXPECT_NEAR(as.derivative_large, -1e6 * l_s, 1e-9 * 1e6 * l_s);
  EXPECT_NEAR(ls.scaled_large, as.scaled_large, 1e-12);
  double euler = 0.0;
  for (const auto& p : s.parameters)
    if (p.name.find("alpha") != std::string::npos) euler += row[index_of(s, p.name)].scaled_large;
  EXPECT_NEAR(euler, q, 1e-12);
  for (const auto& e : row) EXPECT_EQ(e.flag, EntryFlag::Ok);
  EXPECT_EQ(s.evaluations, 1 + 4 * 5);
}

// A log step p (1 +- h) on q = (M_s / 1e5)^3: the central difference is q (3 + h^2) exactly
// (its O(h^2) truncation), and d(M_s lambda_s)/d ln M_s = d(M_s lambda_s)/d ln lambda_s = q.
TEST(Sensitivity, LogStepHasItsSecondOrderTruncation) {
  SensitivityRequest r = request({"material.Ms_A_per_m", "material.lambda_s"}, {});
  r.use_claims = false;
  r.metrics.clear();
  r.functions.push_back(
      {"cube", "-", [](const Model& m) { return std::pow(m.material.Ms_A_per_m / 1e5, 3); }});
  r.functions.push_back({"product", "A/m", [](const Model& m) {
                           return m.material.Ms_A_per_m * m.material.lambda_s;
                         }});
  const SensitivityResult s = run_sensitivity(mdma(), r);
  const double q = s.quantities[0].value, hL = r.step_large, hS = r.step_small;
  EXPECT_EQ(s.parameters[0].step, StepKind::Log);
  EXPECT_NEAR(s.entries[0][0].derivative_large, q * (3 + hL * hL), 1e-12 * q);
  EXPECT_NEAR(s.entries[0][0].derivative_small, q * (3 + hS * hS), 1e-12 * q);
  EXPECT_NEAR(s.entries[0][1].derivative_large, 0.0, 1e-15);
  const double q2 = s.quantities[1].value;
  EXPECT_NEAR(s.entries[1][0].derivative_large, q2, 1e-12 * q2);
  EXPECT_NEAR(s.entries[1][1].derivative_large, q2, 1e-12 * q2);
  EXPECT_EQ(s.flagged(), 0);
}

// A quantity with a jump between the stencil points: the two estimates are 1/(2 h) apart by
// a factor 4, flagged. One that is NaN on one side: nonfinite. A stencil point below a
// parameter's rule (an inner diameter of 0 stepped down): step_refused, with the rule.
TEST(Sensitivity, FlagsNonSmoothAndInvalidPoints) {
  const double Ms0 = mdma().material.Ms_A_per_m;
  SensitivityRequest r = request({"material.Ms_A_per_m"}, {});
  r.use_claims = false;
  r.metrics.clear();
  r.functions.push_back(
      {"jump", "-", [Ms0](const Model& m) { return m.material.Ms_A_per_m > Ms0 ? 1.0 : 0.0; }});
  r.functions.push_back({"smooth", "-", [](const Model& m) { return m.material.Ms_A_per_m; }});
  r.functions.push_back({"nan_above", "-", [Ms0](const Model& m) {
                           return m.material.Ms_A_per_m > 1.005 * Ms0
                                      ? std::numeric_limits<double>::quiet_NaN()
                                      : 1.0;
                         }});
  SensitivityResult s = run_sensitivity(mdma(), r);
  EXPECT_EQ(s.entries[0][0].flag, EntryFlag::Disagree);
  EXPECT_NEAR(s.entries[0][0].scaled_large, 1.0 / (2 * r.step_large), 1e-9);
  EXPECT_NEAR(s.entries[0][0].scaled_small, 1.0 / (2 * r.step_small), 1e-9);
  EXPECT_NEAR(s.entries[0][0].disagreement, 0.75, 1e-9);
  EXPECT_EQ(s.entries[1][0].flag, EntryFlag::Ok);
  EXPECT_EQ(s.entries[2][0].flag, EntryFlag::NonFinite);
  EXPECT_TRUE(std::isnan(s.entries[2][0].derivative_large));
  EXPECT_EQ(s.flagged(), 2);

  SensitivityRequest z = request({"rod3.inner_diameter_m"}, {});
  z.parameters[0].scale = 1e-3;
  z.use_claims = false;
  z.metrics.clear();
  z.functions.push_back({"d", "m", [](const Model& m) { return m.rods[2].inner_diameter_m; }});
  s = run_sensitivity(mdma(), z);
  EXPECT_EQ(s.parameters[0].step, StepKind::Absolute);
  EXPECT_EQ(s.entries[0][0].flag, EntryFlag::StepRefused);
  EXPECT_NE(s.entries[0][0].message.find("must be >= 0"), std::string::npos)
      << s.entries[0][0].message;
  // Identifiability keeps the quantity; the parameter is a column no quantity sees.
  EXPECT_EQ(s.identifiability.quantities.size(), 1u);
  EXPECT_EQ(s.identifiability.column_norm[0], 0.0);
  ASSERT_EQ(s.identifiability.excluded.size(), 1u);
  EXPECT_NE(s.identifiability.excluded[0].find("rod3.inner_diameter_m"), std::string::npos);
}

// Simulated quantities (a claim from two sweep runs, a metric quantity): the two steps agree
// to ~1e-5 where the derivative matters (observed <= 3e-4 for d/d ln M_s and the preload),
// the values are those of run_claims and run_sweep, and the result is bit for bit the same on
// 1 and 3 threads.
TEST(Sensitivity, SmoothQuantitiesAgreeAndThreadCountDoesNotMatter) {
  SensitivityRequest r = request({"material.Ms_A_per_m", "preload.force_N"},
                                 {"stroke_drop_8A", "stroke_um@20C_8A_10Hz"});
  r.threads = 1;
  const SensitivityResult a = run_sensitivity(mdma(), r);
  r.threads = 3;
  const SensitivityResult b = run_sensitivity(mdma(), r);
  ASSERT_EQ(a.quantities.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t j = 0; j < 2; ++j) {
      const SensitivityEntry &x = a.entries[i][j], &y = b.entries[i][j];
      EXPECT_EQ(x.derivative_large, y.derivative_large);
      EXPECT_EQ(x.derivative_small, y.derivative_small);
      EXPECT_EQ(x.flag, EntryFlag::Ok) << a.quantities[i].name << " " << a.parameters[j].name;
      EXPECT_LT(x.disagreement, 3e-3) << a.quantities[i].name << " " << a.parameters[j].name;
      EXPECT_GT(std::fabs(x.scaled_large), 1e-2 * a.quantities[i].scale);
    }
  EXPECT_EQ(a.parameters[1].step, StepKind::Absolute);  // preload: >= 0
  ReproduceOptions o;
  EXPECT_EQ(a.quantities[0].value, run_claims(mdma(), o, {"stroke_drop_8A"})[0].ours);
  SweepRequest sw;
  sw.temperatures_C = {20};
  sw.currents_pp_A = {8};
  sw.frequencies_Hz = {10};
  EXPECT_EQ(a.quantities[1].value, run_sweep(mdma(), sw).points[0].metrics.stroke_um);
  EXPECT_EQ(a.quantities[1].kind, QuantityKind::Metric);
}

// Two parameters that enter only as a product, a third seen by another quantity: one
// near-null direction, (1, -1, 0)/sqrt 2 in (ln a, ln b, ln c); a and b correlate -1; c is
// determined; a parameter no quantity sees has no correlation.
TEST(Identifiability, FindsTheProductPair) {
  const std::vector<std::vector<double>> J = {{1.0, 1.0, 0.0}, {2.0, 2.0, 0.5}, {0.0, 0.0, 3.0}};
  const Identifiability id =
      analyse_identifiability({"q1", "q2", "q3"}, {1.0, 2.0, 1.0}, J, 3, 1e-3);
  ASSERT_EQ(id.directions.size(), 3u);
  EXPECT_EQ(id.rank, 2);
  const Direction& d = id.directions[2];
  EXPECT_TRUE(d.near_null);
  EXPECT_TRUE(d.weak);  // below one tolerance per unit
  EXPECT_FALSE(id.directions[1].near_null);
  EXPECT_FALSE(id.directions[1].weak);  // ~2 tolerances per unit
  EXPECT_NEAR(std::fabs(d.components[0]), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(d.components[0], -d.components[1], 1e-12);
  EXPECT_NEAR(d.components[2], 0.0, 1e-12);
  EXPECT_NEAR(id.correlation[0][1], -1.0, 1e-9);
  EXPECT_LT(std::fabs(id.correlation[0][2]), 1e-3);
  EXPECT_TRUE(std::isinf(id.std_dev[0]));
  EXPECT_TRUE(std::isfinite(id.std_dev[2]));
  EXPECT_NEAR(id.jacobian[1][0], 1.0, 1e-15);  // per tolerance: 2 / 2
  // A fourth parameter that no quantity sees: no correlation, no standard deviation; the
  // product pair stays at -1.
  const Identifiability id4 = analyse_identifiability(
      {"q1", "q2", "q3"}, {1.0, 2.0, 1.0}, {{1, 1, 0, 0}, {2, 2, 0.5, 0}, {0, 0, 3, 0}}, 4, 1e-3);
  EXPECT_EQ(id4.column_norm[3], 0.0);
  EXPECT_TRUE(std::isnan(id4.correlation[3][0]));
  EXPECT_TRUE(std::isnan(id4.std_dev[3]));
  EXPECT_NEAR(id4.correlation[0][1], -1.0, 1e-9);
  EXPECT_EQ(id4.rank, 2);
}

// The same from real finite differences: the sleeve's length and expansion coefficient enter
// eq. 21 only as their product; a second quantity sees the rods' coefficient alone.
TEST(Identifiability, FindsTheSleeveProductEndToEnd) {
  SensitivityRequest r =
      request({"thermal_expansion.sleeve_length_m", "thermal_expansion.sleeve_alpha_per_K",
               "material.alpha_thermal_per_K"},
              {"thermal_model", "rod_alpha"});
  r.functions.push_back({"rod_alpha", "um/(m degC)",
                         [](const Model& m) { return 1e6 * m.material.alpha_thermal_per_K; }, 1.0});
  const SensitivityResult s = run_sensitivity(mdma(), r);
  const Identifiability& id = s.identifiability;
  EXPECT_EQ(id.rank, 2);
  const Direction& d = id.directions.back();
  EXPECT_TRUE(d.near_null);
  EXPECT_NEAR(std::fabs(d.components[0]), std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(d.components[0], -d.components[1], 1e-6);
  EXPECT_NEAR(id.correlation[0][1], -1.0, 1e-6);
  const std::string text = direction_text(d, s.parameters);
  EXPECT_NE(text.find("sleeve_length_m"), std::string::npos) << text;
  EXPECT_NE(text.find("sleeve_alpha_per_K"), std::string::npos) << text;
}

TEST(Sensitivity, RefusesBadRequests) {
  auto err = [](SensitivityRequest r) {
    r.use_claims = false;
    return input_error_of([&] { run_sensitivity(mdma(), r); });
  };
  EXPECT_NE(err(request({"nope"}, {})).find("nope"), std::string::npos);
  EXPECT_NE(err(request({"material.Ms_A_per_m", "material.Ms_A_per_m"}, {})).find("given twice"),
            std::string::npos);
  EXPECT_NE(err(request({"rod3.inner_diameter_m"}, {})).find("needs a scale"), std::string::npos);
  SensitivityRequest q = request({"material.Ms_A_per_m"}, {"no_such_quantity"});
  EXPECT_NE(err(q).find("unknown quantity 'no_such_quantity'"), std::string::npos);
  SensitivityRequest h = request({"material.Ms_A_per_m"}, {});
  h.step_small = 0.02;
  EXPECT_NE(err(h).find("below the large one"), std::string::npos);
  h.step_small = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(err(h).find("step_small"), std::string::npos);
  SensitivityRequest na = request({"material.Ms_A_per_m"}, {"model_rms_200Hz"});
  EXPECT_NE(input_error_of([&] { run_sensitivity(mdma(), na); }).find("not applicable"),
            std::string::npos);
  EXPECT_NE(err(request({}, {})).find("no parameter"), std::string::npos);
}

TEST(Sensitivity, ModelParametersAreWhatAUserVaries) {
  const auto ps = model_parameters(mdma().spec);
  auto has = [&](const std::string& n) {
    for (const auto& p : ps)
      if (p.name == n) return true;
    return false;
  };
  EXPECT_TRUE(has("material.Ms_A_per_m"));
  EXPECT_TRUE(has("rod2.ja.k0_A_per_m"));
  EXPECT_TRUE(has("preload.force_N"));
  EXPECT_FALSE(has("reference.T_ref_C"));
  EXPECT_FALSE(has("rod3.inner_diameter_m"));  // 0
  EXPECT_FALSE(has("thermal_network.coil_resistance_ohm"));
  EXPECT_GT(ps.size(), 40u);
}

}  // namespace
