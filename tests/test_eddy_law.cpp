// The eddy law of eq. (7)'s kappa (options.eddy_law, docs/model.md "The eddy law"): the
// classical section-averaged eddy field of a tube against a direct integration of Faraday's
// and Ampere's laws, and the model's conditions under either law.
#include <gtest/gtest.h>

#include <cmath>

#include "builtin_models.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/magnetic.hpp"

using namespace gmasim;
using namespace gmasim::physics;

namespace {

// kappa rho = the section average of f(r) = integral_r^r1 (s^2 - r2^2)/(2 s) ds, the field lag
// per unit dB/dt times rho, by composite Simpson rules on both integrals (no closed form used).
double kappa_rho_by_quadrature(double r1, double r2) {
  const int n = 2000;  // even
  auto f = [&](double r) {
    const double h = (r1 - r) / n;
    if (h == 0.0) return 0.0;
    double sum = 0.0;
    for (int k = 0; k <= n; ++k) {
      const double s = r + k * h;
      const double w = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
      sum += w * (s * s - r2 * r2) / (2.0 * s);
    }
    return sum * h / 3.0;
  };
  const int m = 400;
  const double h = (r1 - r2) / m;
  double sum = 0.0;
  for (int k = 0; k <= m; ++k) {
    const double r = r2 + k * h;
    const double w = (k == 0 || k == m) ? 1.0 : (k % 2 ? 4.0 : 2.0);
    sum += w * f(r) * 2.0 * r;
  }
  return sum * h / 3.0 / (r1 * r1 - r2 * r2);
}

}  // namespace

TEST(EddyLaw, ClassicalSolidRodIsRSquaredOverEightRho) {
  const double rho = 6e-7;
  EXPECT_DOUBLE_EQ(classical_eddy_coefficient(0.004, 0.0, rho), 0.004 * 0.004 / (8.0 * rho));
  // Equal to eq. 7's printed form with k_j = 2 for a solid rod.
  EXPECT_NEAR(classical_eddy_coefficient(0.004, 0.0, rho),
              eddy_time_constant(1.0, 0.004, 0.0, 2.0, rho), 1e-15);
}

TEST(EddyLaw, ClassicalTubeEqualsTheIntegratedFieldLag) {
  // The MDMA's three rods (Table 2) and a thin tube: the closed form against Simpson's rule
  // (its error ~1e-13 relative at these step counts). The closed form's terms cancel for a
  // thin wall (about (r/t)^2 ulp lost): the tube of r/t = 100 gets 1e-9.
  const double cases[][3] = {
      {0.010, 0.0075, 3e-12}, {0.007, 0.0045, 3e-12}, {0.004, 1e-9, 3e-12}, {0.010, 0.0099, 1e-9}};
  for (const auto& c : cases) {
    const double q = kappa_rho_by_quadrature(c[0], c[1]);
    EXPECT_NEAR(classical_eddy_coefficient(c[0], c[1], 1.0), q, c[2] * q)
        << "r1 " << c[0] << " r2 " << c[1];
  }
  // A thin tube lags by about t^2/3 per unit rho (t the wall): a wall field lag, not r^2/8.
  const double t = 1e-4;
  EXPECT_NEAR(classical_eddy_coefficient(0.010, 0.010 - t, 1.0), t * t / 3.0, 0.02 * t * t / 3.0);
}

TEST(EddyLaw, OptionSelectsKappaInTheConditionsAndLeavesTheRestAlone) {
  const Model& table4 = gmasim_test::mdma();
  ASSERT_EQ(table4.options.eddy_law, EddyLaw::Table4);  // the paper's law is the default
  ModelSpec spec = builtin_model_spec();
  spec.set_option("options.eddy_law", "classical");
  const Model classical = compile(spec);
  ASSERT_EQ(classical.options.eddy_law, EddyLaw::Classical);
  const Conditions a = make_conditions(table4, 70.0), b = make_conditions(classical, 70.0);
  ASSERT_EQ(a.rods.size(), b.rods.size());
  // Table 4's k_j give 5.6 / 11.5 / 13.3 times the classical kappa for rods 1 / 2 / 3.
  const double ratio[] = {5.65, 11.55, 13.33};
  for (std::size_t i = 0; i < a.rods.size(); ++i) {
    const auto& ra = a.rods[i];
    const auto& rb = b.rods[i];
    EXPECT_DOUBLE_EQ(
        ra.eddy_geometry_s_m_per_H,
        eddy_time_constant(1.0, ra.r_outer_m, ra.r_inner_m, table4.rods[i].k_j, ra.rho_ohm_m));
    EXPECT_DOUBLE_EQ(rb.eddy_geometry_s_m_per_H,
                     classical_eddy_coefficient(rb.r_outer_m, rb.r_inner_m, rb.rho_ohm_m));
    EXPECT_NEAR(ra.eddy_geometry_s_m_per_H / rb.eddy_geometry_s_m_per_H, ratio[i], 0.01) << i;
    EXPECT_EQ(ra.rho_ohm_m, rb.rho_ohm_m);
    EXPECT_EQ(ra.series_reluctance_per_H, rb.series_reluctance_per_H);
  }
}
