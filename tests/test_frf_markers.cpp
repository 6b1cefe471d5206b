// linear_frf_markers (src/experiments/frf_markers.cpp) reads |Y| of its 4000-point log grid only
// where the markers' rules can pick a point (a coarse scan, then windows): its markers must be
// those of the whole dense curve (find_resonance_Hz, find_bandwidth_3dB_Hz), bit for bit, on
// the MDMA's bias points and on linearisations whose resonances and notches are much sharper
// or lie elsewhere in the band than the built-in model's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "experiments_fixtures.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/mechanics/mechanics.hpp"

using namespace gmasim;

namespace {

// The markers of the dense curve: |Y| at every point of linear_frf_markers' grid.
LinearFrfMarkers dense_markers(const SmallSignalModel& L, double f0, double f1) {
  constexpr int n = 4000;
  std::vector<double> f(n), mag(n);
  for (int k = 0; k < n; ++k) {
    f[static_cast<std::size_t>(k)] = f0 * std::pow(f1 / f0, static_cast<double>(k) / (n - 1));
    mag[static_cast<std::size_t>(k)] = std::abs(L.response(f[static_cast<std::size_t>(k)]));
  }
  return {find_resonance_Hz(f, mag), find_bandwidth_3dB_Hz(f, mag)};
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

void expect_dense(const SmallSignalModel& L, double f0, double f1, const char* what, int i) {
  const LinearFrfMarkers got = linear_frf_markers(L, f0, f1), want = dense_markers(L, f0, f1);
  EXPECT_TRUE(same_bits(got.first_resonance_Hz, want.first_resonance_Hz))
      << what << " " << i << ": peak " << got.first_resonance_Hz << " Hz, dense grid "
      << want.first_resonance_Hz << " Hz";
  EXPECT_TRUE(same_bits(got.bandwidth_3dB_Hz, want.bandwidth_3dB_Hz))
      << what << " " << i << ": bandwidth " << got.bandwidth_3dB_Hz << " Hz, dense grid "
      << want.bandwidth_3dB_Hz << " Hz";
}

}  // namespace

TEST(FrfMarkers, EqualTheDenseGridsAtTheMdmaBiasPoints) {
  const Model& m = gmasim_experiments_test::mdma();
  int i = 0;
  for (double T : {20.0, 150.0})
    for (double bias : {1.0, 4.0}) {
      const Conditions c = make_conditions(m, T);
      const SmallSignalModel L =
          linearise(m, c, settle_at_bias(m, c, bias, BiasState::Anhysteretic));
      expect_dense(L, 1.0, 5000.0, "T, bias", i);
      expect_dense(L, 20.0, 20000.0, "T, bias (20 Hz .. 20 kHz)", i++);
    }
}

// The MDMA's linearisation at 20 degC with its oscillators moved and sharpened at random: the
// sensor mount's damping ratio down to 0.001 (the fit's bounds stop at 0.01) and its resonance
// over 500 Hz .. 3 kHz, the rods' modes brought into the band (down to ~600 Hz) with a tenth to
// three times their damping, the eddy lags scaled by 0.1 .. 10.
TEST(FrfMarkers, EqualTheDenseGridsWithSharpAndMovedResonances) {
  const Model& m = gmasim_experiments_test::mdma();
  const Conditions c = make_conditions(m, 20.0);
  const SmallSignalModel L0 = linearise(m, c, settle_at_bias(m, c, 1.0, BiasState::Anhysteretic));
  ASSERT_TRUE(L0.sensor_mount);
  std::mt19937 g(20261127);
  auto log_uniform = [&](double lo, double hi) {
    return lo * std::pow(hi / lo, std::uniform_real_distribution<double>(0.0, 1.0)(g));
  };
  for (int trial = 0; trial < 24; ++trial) {
    SmallSignalModel L = L0;
    const double f_sm = log_uniform(500.0, 3000.0), zeta_sm = log_uniform(1e-3, 0.1);
    L.sm_stiffness_N_per_m = L.sm_mass_kg * std::pow(2.0 * M_PI * f_sm, 2);
    L.sm_damping_N_s_per_m = 2.0 * zeta_sm * std::sqrt(L.sm_stiffness_N_per_m * L.sm_mass_kg);
    for (std::size_t i = 0; i < L.mass_kg.size(); ++i) {
      L.stiffness_N_per_m[i] *= log_uniform(0.01, 1.0);
      L.damping_N_s_per_m[i] *= log_uniform(0.1, 3.0);
      const double eddy = log_uniform(0.1, 10.0);
      L.tau_s[i] *= eddy;
      L.kappa_s_m_per_H[i] *= eddy;
    }
    if (trial % 4 == 0) L.kappa_s_m_per_H.assign(L.kappa_s_m_per_H.size(), 0.0);
    expect_dense(L, 1.0, 5000.0, "trial", trial);
  }
}
