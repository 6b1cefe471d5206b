// Issue 38 item 1: the step's mechanics laws are written once (gmasim/physics/laws-inl.h) over a
// number type; the scalar step instantiates them with double, the lanes with a Highway vector.
// Each lane must then equal the scalar instance bit for bit -- by construction, which this test
// checks on inputs that reach every branch of the laws (|m| beyond 1: libm's cos; prestress above
// sigma_s; the tanh anchor near, far and absent; the oscillator under-, over- and critically
// damped, steps within the series' halvings, beyond four of them and beyond its caps (the closed
// form); the decay cached and not), on every SIMD target compiled in that this CPU runs.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "gmasim/physics/laws.hpp"
#include "lanes/lane_data.hpp"

namespace {

using namespace gmasim;
using namespace gmasim::lanes;

constexpr std::size_t kProbeLanes = 256;

std::vector<double> probe_inputs() {
  std::mt19937_64 rng(20261207);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  auto uni = [&](double a, double b) { return a + (b - a) * u01(rng); };
  auto log_uni = [&](double a, double b) { return a * std::pow(b / a, u01(rng)); };
  const std::size_t n = kProbeLanes;
  std::vector<double> in(static_cast<std::size_t>(kLawProbeInCount) * n);
  auto at = [&](int f, std::size_t j) -> double& {
    return in[static_cast<std::size_t>(f) * n + j];
  };
  const double nan = std::nan("");
  for (std::size_t j = 0; j < n; ++j) {
    const double Ms = uni(6e5, 8e5);
    at(kPiM, j) = uni(-1.3, 1.3) * Ms;  // |m| > 1 in about a quarter of the lanes
    at(kPiInvMsTE, j) = 1.0 / Ms;
    at(kPiInvEs, j) = 1.0 / uni(40e9, 100e9);
    at(kPiRot, j) = uni(0.5e-11, 3e-11);
    at(kPiCoupling, j) = uni(1e-3, 3e-3);
    at(kPiMu0Ms2, j) = uni(2e5, 1e6);
    at(kPiS, j) = uni(0.0, 0.4) * at(kPiMu0Ms2, j);
    at(kPiInvMsStrain, j) = 1.0 / uni(6e5, 8e5);
    at(kPiLambdaS, j) = uni(800e-6, 1200e-6);
    at(kPiSigmaP, j) = uni(1e6, 60e6);  // sigma_s = lambda_s E / 2: 16-60 MPa
    const double area = uni(1e-4, 3e-4), length = uni(0.02, 0.1);
    at(kPiArea, j) = area;
    at(kPiAreaOverLength, j) = area / length;
    at(kPiLengthOverArea, j) = length / area;
    // the tanh's anchor: none, near the argument (within 1/8) or far
    const int anchor = static_cast<int>(j % 3);
    const double y = anchor == 0 ? nan : uni(-8.0, -0.01);
    at(kPiPrestressY, j) = y;
    at(kPiPrestressE, j) = anchor == 0 ? 0.0 : std::exp(y);
    at(kPiFixedCompliance, j) = log_uni(1e-9, 1e-7);
    // rigid joints (0: eq. 14, 17 exactly) in a third of the lanes, bonded ones in the others
    at(kPiJointCompliance, j) = j % 3 == 1 ? 0.0 : log_uni(1e-11, 1e-9);
    at(kPiK0, j) = log_uni(1e6, 1e8);
    const double m = uni(0.01, 0.1);
    at(kPiMass, j) = m;
    at(kPiInvMass, j) = 1.0 / m;
    // damping from none to 3x critical at K0 (and critical exactly in some lanes)
    const double crit = 2.0 * std::sqrt(at(kPiK0, j) * m);
    at(kPiDamping, j) = j % 17 == 5 ? crit : uni(0.0, 3.0) * crit;
    at(kPiH, j) = log_uni(1e-7, 3e-2);  // w_n h from 1e-4 to beyond the series' cap of 256
    at(kPiF0, j) = uni(-500.0, 500.0);
    at(kPiX, j) = uni(-50e-6, 50e-6);
    at(kPiV, j) = uni(-0.1, 0.1);
    // the decay's cache: its own e^(tau/2) (a hit) in half the lanes, none in the others
    const double half_tau = 0.5 * (-(at(kPiDamping, j) * at(kPiInvMass, j)) * at(kPiH, j));
    const bool hit = j % 2 == 0;
    at(kPiDecayY, j) = hit ? half_tau : nan;
    at(kPiDecayE, j) = hit ? std::exp(half_tau) : 0.0;
    at(kPiQ0, j) = uni(-20e-6, 20e-6);
    at(kPiQ1, j) = uni(-20e-6, 20e-6);
    at(kPiZ, j) = uni(-20e-6, 20e-6);
    at(kPiZv, j) = uni(-0.05, 0.05);
  }
  return in;
}

// The scalar instance (gmasim::physics, double) of what MechanicsLaws computes for lane j.
std::vector<double> scalar_outputs(const std::vector<double>& in, std::size_t j) {
  const std::size_t n = kProbeLanes;
  auto at = [&](int f) { return in[static_cast<std::size_t>(f) * n + j]; };
  const physics::DeltaETerms dE{at(kPiInvEs), at(kPiRot), at(kPiCoupling), at(kPiMu0Ms2), at(kPiS)};
  physics::ExpPoint prestress{at(kPiPrestressY), at(kPiPrestressE)};
  const physics::RodMechanics k = physics::rod_mechanics(
      at(kPiM), at(kPiInvMsTE), dE, at(kPiInvMsStrain), at(kPiLambdaS), at(kPiSigmaP),
      4.0 * at(kPiSigmaP) / at(kPiLambdaS), at(kPiArea), at(kPiAreaOverLength),
      at(kPiLengthOverArea), at(kPiJointCompliance), prestress);
  const double compliance[1] = {k.compliance_m_per_N};
  const int self[1] = {0};
  const double k_load = physics::chain_stiffness(at(kPiFixedCompliance), compliance, self, 1);
  const double K = physics::mid_step_stiffness(at(kPiK0), k.k_rod_N_per_m, k_load);
  double x = at(kPiX), v = at(kPiV), z = at(kPiZ), zv = at(kPiZv);
  physics::ExpPoint decay{at(kPiDecayY), at(kPiDecayE)}, mount = decay;
  physics::oscillator_step(at(kPiMass), at(kPiInvMass), at(kPiDamping), K, at(kPiF0), k.F_N,
                           at(kPiH), x, v, decay);
  physics::base_excited_step(at(kPiMass), at(kPiInvMass), at(kPiDamping), K, at(kPiQ0), at(kPiQ1),
                             at(kPiH), z, zv, mount);
  return {k.E_Pa,
          k.lambda,
          k.F_N,
          k.k_rod_N_per_m,
          k.compliance_m_per_N,
          prestress.y,
          prestress.e,
          k_load,
          K,
          x,
          v,
          decay.y,
          decay.e,
          z,
          zv,
          mount.y,
          mount.e};
}

bool same_bits(double a, double b) {
  std::uint64_t x = 0, y = 0;
  std::memcpy(&x, &a, sizeof x);
  std::memcpy(&y, &b, sizeof y);
  return x == y;
}

TEST(LawsLanes, EachLaneIsTheScalarInstanceBitForBit) {
  const std::vector<double> in = probe_inputs();
  const std::size_t n = kProbeLanes;
  std::vector<std::vector<double>> want(n);
  for (std::size_t j = 0; j < n; ++j) want[j] = scalar_outputs(in, j);
  // the inputs reach the branches they are meant to
  int beyond_cap = 0, long_series = 0, over = 0, above_ss = 0, cos_libm = 0;
  for (std::size_t j = 0; j < n; ++j) {
    auto at = [&](int f) { return in[static_cast<std::size_t>(f) * n + j]; };
    const double K = want[j][kPoK], m = at(kPiMass), c = at(kPiDamping), h = at(kPiH);
    const double half_tau = -0.5 * c / m * h, u = half_tau * half_tau - K / m * h * h;
    beyond_cap += (u < 0 && -u > physics::kOscillatorSeriesUnder) || (u > 4.0);
    long_series += u < -4.0 && -u <= physics::kOscillatorSeriesUnder;
    over += u > 0.0;
    above_ss += at(kPiSigmaP) > 0.5 * at(kPiLambdaS) * want[j][kPoE];
    cos_libm += std::fabs(at(kPiM) * at(kPiInvMsTE)) > 1.0;
  }
  std::printf(
      "branches: %d beyond the series' caps, %d long series, %d over-damped, %d above "
      "sigma_s, %d with |m| > 1\n",
      beyond_cap, long_series, over, above_ss, cos_libm);
  EXPECT_GT(beyond_cap, 5);
  EXPECT_GT(long_series, 5);
  EXPECT_GT(over, 5);
  EXPECT_GT(above_ss, 5);
  EXPECT_GT(cos_libm, 5);

  std::vector<int64_t> targets;
  for (int64_t t : hwy::SupportedAndGeneratedTargets()) targets.push_back(t);
  ASSERT_FALSE(targets.empty());
  for (int64_t target : targets) {
    hwy::SetSupportedTargetsForTest(target);
    std::vector<double> out(static_cast<std::size_t>(kLawProbeOutCount) * n, -1.0);
    mechanics_laws_dispatch(in.data(), out.data(), n);
    int differ = 0;
    for (std::size_t j = 0; j < n; ++j)
      for (int f = 0; f < kLawProbeOutCount; ++f) {
        const double got = out[static_cast<std::size_t>(f) * n + j];
        if (!same_bits(got, want[j][static_cast<std::size_t>(f)])) {
          if (++differ <= 5)
            ADD_FAILURE() << hwy::TargetName(target) << ": lane " << j << " output " << f << " is "
                          << got << ", the scalar instance "
                          << want[j][static_cast<std::size_t>(f)];
        }
      }
    std::printf("%s: %d of %zu numbers differ from the scalar instance\n", hwy::TargetName(target),
                differ, n * static_cast<std::size_t>(kLawProbeOutCount));
    EXPECT_EQ(differ, 0) << hwy::TargetName(target);
  }
  hwy::SetSupportedTargetsForTest(0);
}

}  // namespace
