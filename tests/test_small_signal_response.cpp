// SmallSignalModel::response (src/mechanics/linearise.cpp) solves its n x n system with
// Eigen's PartialPivLU on max-size (stack) matrices, without heap: the frequency response must
// be what Eigen's PartialPivLU<MatrixXcd> gives, bit for bit (the identify objective's
// first-resonance target reads the peak of 4000 of them, so one flipped bit changes the search's
// path). The reference below is the response as it was written with Eigen.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <complex>
#include <cstring>
#include <random>
#include <vector>

#include "experiments_fixtures.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/mechanics/mechanics.hpp"
#include "gmasim/physics/magnetic.hpp"

using namespace gmasim;

namespace {

using cd = std::complex<double>;

cd eigen_response(const SmallSignalModel& L, double f_Hz) {
  const auto N = static_cast<Eigen::Index>(L.n);
  const auto n = static_cast<std::size_t>(L.n);
  const cd sj(0.0, 2.0 * physics::kPi * f_Hz);
  Eigen::MatrixXcd A = Eigen::MatrixXcd::Identity(N, N);
  Eigen::VectorXcd b(N), dM(N);
  if (L.consistent) {
    for (std::size_t i = 0; i < n; ++i) {
      const auto ei = static_cast<Eigen::Index>(i);
      b(ei) = L.port_b_At_per_A[i];
      for (std::size_t j = 0; j < n; ++j)
        A(ei, static_cast<Eigen::Index>(j)) =
            L.port_S_per_H[i * n + j] * L.area_m2[j] * physics::kMu0 * (1.0 + L.chi[j]);
      A(ei, ei) +=
          L.length_m[i] * (1.0 + L.kappa_s_m_per_H[i] * sj * physics::kMu0 * (1.0 + L.chi[i]));
    }
    const Eigen::VectorXcd dH = A.partialPivLu().solve(b);
    for (std::size_t i = 0; i < n; ++i)
      dM(static_cast<Eigen::Index>(i)) = L.chi[i] * dH(static_cast<Eigen::Index>(i));
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      const auto ei = static_cast<Eigen::Index>(i);
      const cd lag_chi = L.chi[i] / (1.0 + L.tau_s[i] * sj);
      b(ei) = lag_chi * L.g_A_per_m_per_A[i];
      for (std::size_t j = 0; j < n; ++j)
        A(ei, static_cast<Eigen::Index>(j)) -= lag_chi * L.G[i * n + j];
    }
    dM = A.partialPivLu().solve(b);
  }
  cd Y = 0.0, Q = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    cd dF = 0.0;
    for (std::size_t j = 0; j < n; ++j)
      dF += L.D_N_per_A_per_m[i * n + j] * dM(static_cast<Eigen::Index>(j));
    const cd X =
        dF / (L.mass_kg[i] * sj * sj + L.damping_N_s_per_m[i] * sj + L.stiffness_N_per_m[i]);
    Y += X;
    if (L.sensor_mount) Q += L.recoil_per_x[i] * X;
  }
  if (L.sensor_mount)
    Y -= Q * sj * sj * L.sm_mass_kg /
         (L.sm_mass_kg * sj * sj + L.sm_damping_N_s_per_m * sj + L.sm_stiffness_N_per_m);
  return Y;
}

bool same_bits(cd a, cd b) { return std::memcmp(&a, &b, sizeof(cd)) == 0; }

// A random small-signal model of n rods: entries of either sign over six decades, with
// repeated rows and zero entries now and then (pivot ties and exact zeros).
SmallSignalModel random_model(int n, bool consistent, std::mt19937& g) {
  std::normal_distribution<double> d;
  auto v = [&](std::size_t k, double scale) {
    std::vector<double> x(k);
    for (auto& e : x) e = scale * d(g) * std::pow(10.0, d(g));
    return x;
  };
  const auto un = static_cast<std::size_t>(n);
  SmallSignalModel L;
  L.n = n;
  L.consistent = consistent;
  L.chi = v(un, 10.0);
  L.tau_s = v(un, 1e-4);
  L.g_A_per_m_per_A = v(un, 1e3);
  L.G = v(un * un, 1e-2);
  L.port_S_per_H = v(un * un, 1e7);
  L.port_b_At_per_A = v(un, 1e2);
  L.length_m = v(un, 0.03);
  L.kappa_s_m_per_H = v(un, 1e-3);
  L.area_m2 = v(un, 1e-4);
  L.D_N_per_A_per_m = v(un * un, 1e-3);
  L.mass_kg = v(un, 0.1);
  L.damping_N_s_per_m = v(un, 10.0);
  L.stiffness_N_per_m = v(un, 1e7);
  L.sensor_mount = (g() & 1U) != 0;
  L.recoil_per_x = v(un, 0.1);
  L.sm_mass_kg = 0.02;
  L.sm_stiffness_N_per_m = 1.3e6;
  L.sm_damping_N_s_per_m = 6.0;
  if (n > 1 && g() % 4 == 0) {  // two equal rows: a zero pivot
    for (std::size_t j = 0; j < un; ++j) L.port_S_per_H[un + j] = L.port_S_per_H[j];
    for (std::size_t j = 0; j < un; ++j) L.G[un + j] = L.G[j];
  }
  if (g() % 5 == 0) L.port_S_per_H[0] = L.G[0] = 0.0;
  return L;
}

}  // namespace

TEST(SmallSignalResponse, EqualsEigensPartialPivLuBitForBit) {
  std::mt19937 g(20261126);
  long compared = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = 1 + trial % 10;  // beyond 8 rods: Eigen's own path
    const SmallSignalModel L = random_model(n, trial % 3 != 0, g);
    for (double f : {0.0, 1.0, 37.3, 1270.0, 4999.0}) {
      const cd want = eigen_response(L, f), got = L.response(f);
      ASSERT_TRUE(same_bits(want, got) || (std::isnan(want.real()) && std::isnan(got.real())))
          << "n " << n << " trial " << trial << " f " << f << ": " << got << " vs Eigen " << want;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 15000);
}

TEST(SmallSignalResponse, MdmaBiasPointEqualsEigenOnTheMarkersGrid) {
  const Model& m = gmasim_experiments_test::mdma();
  const Conditions c = make_conditions(m, 20.0);
  const SmallSignalModel L = linearise(m, c, settle_at_bias(m, c, 1.0, BiasState::Anhysteretic));
  ASSERT_TRUE(L.consistent);
  for (int k = 0; k < 4000; ++k) {  // linear_frf_markers' grid over 1 .. 5000 Hz
    const double f = std::pow(5000.0, k / 3999.0);
    ASSERT_TRUE(same_bits(eigen_response(L, f), L.response(f))) << f << " Hz";
  }
}
