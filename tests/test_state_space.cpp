// The linearised plant as a state space (issue 40 item 1; gmasim/mechanics/state_space.hpp):
// its transfer function against SmallSignalModel::response (the same equations, written as
// x' = A x + B u), in both magnetic states and both sensor-mount bases; its DC gain; its poles
// (a stable plant); and its flux-density output against the time-domain step's.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <cstdio>

#include "builtin_models.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/mechanics/mechanics.hpp"
#include "gmasim/mechanics/state_space.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "mechanics/dense.hpp"

using namespace gmasim;

namespace {

struct Plant {
  SmallSignalModel lin;
  StateSpace ss;
};
Plant plant(const Model& m, double T_C, double bias_A) {
  const Conditions c = make_conditions(m, T_C);
  const SmallSignalModel lin =
      linearise(m, c, settle_at_bias(m, c, bias_A, BiasState::Anhysteretic));
  return {lin, state_space(m, lin)};
}

// |ss.response - lin.response| / |lin.response| over 1 Hz - 20 kHz.
double worst_mismatch(const Plant& p) {
  double worst = 0.0;
  for (double f = 1.0; f <= 20000.0; f *= 1.07) {
    const std::complex<double> want = p.lin.response(f);
    worst = std::max(worst, std::abs(p.ss.response(f) - want) / std::abs(want));
  }
  return worst;
}

}  // namespace

TEST(StateSpace, TransferFunctionIsTheLinearisations) {
  struct Case {
    const char* what;
    Model m;
  };
  const Case cases[] = {
      {"built-in (consistent, recoil mount)", compile(builtin_model_spec())},
      {"mount on the output", gmasim_test::mdma_with_option("options.sensor_mount_base", "output")},
      {"printed magnetic state",
       load_model(std::string(GMASIM_SOURCE_DIR) + "/models/mdma_printed.toml")},
  };
  for (const Case& k : cases)
    for (double T : {20.0, 70.0}) {
      const Plant p = plant(k.m, T, 1.0);
      const double e = worst_mismatch(p);
      EXPECT_LT(e, 1e-13) << k.what << " at " << T << " degC";  // observed <= 3.9e-15
      const double dc = p.lin.response(0.0).real();
      EXPECT_NEAR(p.ss.dc_gain() / dc, 1.0, 1e-12) << k.what;
      for (const auto& pole : p.ss.poles()) EXPECT_LT(pole.real(), 0.0) << k.what;  // stable
      std::printf("%s, %.0f degC: %d states, |ss - lin| %.3g relative, DC %.4g um/A\n", k.what, T,
                  p.ss.n_states, e, 1e6 * p.ss.dc_gain());
    }
}

// The names and units a control engineer reads: n rods' fields, displacements and velocities,
// then the probe's two states; outputs y [m] and B [T].
TEST(StateSpace, StatesAreNamedWithTheirUnits) {
  const Plant p = plant(compile(builtin_model_spec()), 20.0, 1.0);
  ASSERT_EQ(p.ss.n_states, 11);
  EXPECT_EQ(p.ss.states.front(), "rod1_H");
  EXPECT_EQ(p.ss.state_units.front(), "A/m");
  EXPECT_EQ(p.ss.states[3], "rod1_x");
  EXPECT_EQ(p.ss.state_units[8], "m/s");
  EXPECT_EQ(p.ss.states.back(), "probe_e_dot");
  ASSERT_EQ(p.ss.outputs.size(), 2u);
  EXPECT_EQ(p.ss.output_units[0], "m");
  EXPECT_EQ(p.ss.output_units[1], "T");
  EXPECT_EQ(p.ss.A.size(), 121u);
  // The recoil mount's antiresonance is a pair of lightly damped zeros near the bracket's f_n.
  bool near_mount = false;
  const double fn = std::sqrt(1.3e6 / 0.02) / (2.0 * M_PI);
  for (const auto& z : p.ss.zeros())
    if (std::abs(std::abs(z) / (2.0 * M_PI) / fn - 1.0) < 0.2) near_mount = true;
  EXPECT_TRUE(near_mount);
}

// The poles and zeros are the transfer function's: k prod(s - z) / prod(s - p), its gain k fixed
// at 1 Hz, gives the response from 10 Hz to 10 kHz. 11 states and relative degree 3 (dI -> dH ->
// force -> x): 8 finite zeros.
TEST(StateSpace, PolesAndZerosGiveTheTransferFunction) {
  const Plant p = plant(compile(builtin_model_spec()), 70.0, 1.0);
  const auto poles = p.ss.poles(), zeros = p.ss.zeros();
  ASSERT_EQ(zeros.size(), 8u);
  auto zpk = [&](double f) {
    const std::complex<double> s(0.0, 2.0 * M_PI * f);
    std::complex<double> v = 1.0;
    for (const auto& z : zeros) v *= s - z;
    for (const auto& q : poles) v /= s - q;
    return v;
  };
  const std::complex<double> k = p.ss.response(1.0) / zpk(1.0);
  double worst = 0.0;
  for (double f = 10.0; f <= 10000.0; f *= 1.3)
    worst = std::max(worst, std::abs(k * zpk(f) / p.ss.response(f) - 1.0));
  EXPECT_LT(worst, 1e-11);  // observed 6.7e-13 (shift-invert; the QZ pencil gave 8.1e-12)
  std::printf("zpk vs state space: %.3g relative\n", worst);
}

// The flux-density output at DC against the step itself: from the settled bias, the current
// held at bias +- 10 uA until the eddy lag has died out, B's central difference (the law's
// irreversible part enters at second order in the step, as in coil_inductance).
TEST(StateSpace, FluxDensityOutputMatchesTheStep) {
  const Model m = compile(builtin_model_spec());
  const Conditions c = make_conditions(m, 20.0);
  const State bias = settle_at_bias(m, c, 1.0, BiasState::Anhysteretic);
  const StateSpace ss = state_space(m, linearise(m, c, bias));
  auto B_after = [&](double I) {
    State s = bias;
    run_loop(m, c, s, StepGrid::covering(0.0, 0.05, 5e-6, "test"), HeldCurrent{I});
    return s.B_T;
  };
  const double d = 1e-5, d1 = (B_after(1.0 + d) - B_after(1.0 - d)) / (2 * d),
               d2 = (B_after(1.0 + 2 * d) - B_after(1.0 - 2 * d)) / (4 * d);
  const double step = 2 * d1 - d2;
  const double e = std::fabs(ss.dc_gain(1) / step - 1.0);
  EXPECT_LT(e, 1e-4);  // observed: the printout
  std::printf("dB/dI at DC: state space %.6g T/A, step %.6g T/A (%.3g)\n", ss.dc_gain(1), step, e);
}

// The time domain (issue 40 item 2's check, here against the library's own step): from the
// settled bias, a current step dI; the nonlinear step's y(t) - y(0) against the state space's
// step response (exact discretisation, x_{k+1} = e^{Ah} x_k + A^-1 (e^{Ah} - I) B dI) every 0.1 ms
// to 20 ms, relative to the final value. Returns the worst difference.
double step_response_mismatch(double dI) {
  const Model m = compile(builtin_model_spec());
  const Conditions c = make_conditions(m, 20.0);
  const State bias = settle_at_bias(m, c, 1.0, BiasState::Anhysteretic);
  const StateSpace ss = state_space(m, linearise(m, c, bias));
  const int n = ss.n_states;
  const double h = 2e-6;
  using Mat = Eigen::MatrixXd;
  const Mat A = Eigen::Map<const Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(ss.A.data(), n, n);
  const Eigen::VectorXd B = Eigen::Map<const Eigen::VectorXd>(ss.B.data(), n);
  const Eigen::RowVectorXd C = Eigen::Map<const Eigen::RowVectorXd>(ss.C.data(), n);
  const Mat Phi = dense::exponential(A * h);
  const Eigen::VectorXd Gamma = A.partialPivLu().solve((Phi - Mat::Identity(n, n)) * B * dI);
  // The step ramps the current over its first h (step() interpolates the current linearly over
  // a step): to second order in h, the ideal step's response h/2 later. So the state space is
  // sampled at t_k - h/2: its state after h/2 of the step, then whole steps.
  const Mat half = dense::exponential(A * (0.5 * h));
  Eigen::VectorXd x = A.partialPivLu().solve((half - Mat::Identity(n, n)) * B * dI);
  State s = bias;
  const double y0 = s.y_m, final_m = ss.dc_gain() * dI;
  double worst = 0.0;
  for (int k = 1; k <= 10000; ++k) {
    if (k > 1) x = Phi * x + Gamma;
    step(m, c, s, {1.0 + dI, h});
    s.t_s = k * h;
    if (k % 50 == 0)
      worst = std::max(worst, std::fabs((s.y_m - y0) - C.dot(x)) / std::fabs(final_m));
  }
  return worst;
}

// In the small-signal limit the nonlinear step follows the state space within the 0.5 %
// of the final value (0.1 mA: observed 0.085 %). The difference grows in proportion to the step
// (1 mA: 0.83 %, issue 40's 1 mA stimulus does not meet its 0.5 %): it is the Jiles-Atherton
// law's irreversible response, dM_irr = (M_an - M_irr) dH / k with M_an - M_irr = O(dH) on the
// minor loop, which the linearisation (the reversible slope) leaves out by construction.
TEST(StateSpace, StepResponseMatchesTheNonlinearStepInTheSmallSignalLimit) {
  const double small = step_response_mismatch(1e-4), large = step_response_mismatch(1e-3);
  EXPECT_LT(small, 5e-3);
  EXPECT_NEAR(large / small, 10.0, 3.0);  // first order in the step's size
  std::printf("current step vs state space: worst %.3g (0.1 mA), %.3g (1 mA) of the final value\n",
              small, large);
}

// The plant split at the sensor mount (issue 40, item 1): the stack's block and the mount's,
// put together as `interconnection` says, give the whole plant's response; the mount's block is
// the bracket's closed form; without a mount the stack is the plant.
TEST(StateSpace, TheMountIsASeparableBlock) {
  struct Case {
    const char* what;
    Model m;
    const char* interconnection;
  };
  Model no_mount = compile(builtin_model_spec());
  no_mount.sensor_mount.enabled = false;
  const Case cases[] = {
      {"recoil (built-in)", compile(builtin_model_spec()), "y = y_stack + dy"},
      {"on the output", gmasim_test::mdma_with_option("options.sensor_mount_base", "output"),
       "y = dy"},
      {"no mount", no_mount, "y = y_stack"},
  };
  for (const Case& k : cases)
    for (double T : {20.0, 70.0}) {
      const Plant p = plant(k.m, T, 1.0);
      EXPECT_EQ(p.ss.interconnection, k.interconnection) << k.what;
      ASSERT_EQ(p.ss.blocks.size(), k.m.sensor_mount.enabled ? 2u : 1u) << k.what;
      const StateSpace& stack = p.ss.blocks[0];
      EXPECT_EQ(stack.outputs[0], "y_stack");
      EXPECT_EQ(stack.outputs[1], "q");
      double worst = 0.0, worst_mount = 0.0;
      for (double f = 1.0; f <= 20000.0; f *= 1.07) {
        const std::complex<double> want = p.ss.response(f);
        worst = std::max(worst, std::abs(p.ss.blocks_response(f) - want) / std::abs(want));
        if (p.ss.blocks.size() < 2) continue;
        // the bracket: z = q (c s + k)/(m s^2 + c s + k); dy = z - q = -q m s^2/(...) on the
        // recoil, z on the output
        const auto& sm = k.m.sensor_mount;
        const std::complex<double> s(0.0, 2.0 * M_PI * f);
        const std::complex<double> den =
            sm.mass_kg * s * s + sm.damping_N_s_per_m * s + sm.stiffness_N_per_m;
        const std::complex<double> G =
            std::string(k.interconnection) == "y = y_stack + dy"
                ? -sm.mass_kg * s * s / den
                : (sm.damping_N_s_per_m * s + sm.stiffness_N_per_m) / den;
        // Relative to max(|G|, |D| = 1): on the recoil D = -1 and C (sI - A)^-1 B -> 1 as f -> 0,
        // so any realisation of -m s^2/(...) with q alone as input cancels to |G| ~ (f/f_n)^2
        // there (6e-7 at 1 Hz); its error is an ulp of D's 1, not of G.
        worst_mount = std::max(
            worst_mount, std::abs(p.ss.blocks[1].response(f) - G) / std::max(std::abs(G), 1.0));
      }
      // observed: blocks vs whole <= 1.7e-14, mount vs closed form <= 1.7e-14
      EXPECT_LT(worst, 1e-12) << k.what << " at " << T << " degC";
      EXPECT_LT(worst_mount, 1e-12) << k.what;
      std::printf("%s, %.0f degC: blocks vs whole %.3g, mount vs closed form %.3g\n", k.what, T,
                  worst, worst_mount);
    }
}
