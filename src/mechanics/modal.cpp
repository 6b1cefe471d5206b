// The mechanics module: the modes of the rods' chain of eq. (15) at a state
// (gmasim/mechanics/mechanics.hpp, mechanical_modes).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "gmasim/mechanics/mechanics.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim {
using physics::kTwoPi;

std::vector<Mode> mechanical_modes(const Model& m, const Conditions& c, const State& s) {
  (void)m;
  const auto N = static_cast<Eigen::Index>(s.rods.size());
  // Eq. (15) with the diagonal M, C, K of eq. (16), (24), (25); assembled as full
  // matrices so a model with coupling terms would be handled the same way.
  Eigen::MatrixXd Mm = Eigen::MatrixXd::Zero(N, N), Cm = Mm, Km = Mm;
  for (Eigen::Index i = 0; i < N; ++i) {
    const auto& rc = c.rods[static_cast<std::size_t>(i)];
    Mm(i, i) = rc.mass_osc_kg;
    Cm(i, i) = rc.damping_osc_N_s_per_m;
    Km(i, i) = oscillator_stiffness(c, s, static_cast<int>(i));
  }
  // Undamped modes: K v = w^2 M v; classical modal damping zeta = v'Cv / (2 w v'Mv).
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Km, Mm);
  std::vector<Mode> modes;
  for (Eigen::Index k = 0; k < N; ++k) {
    const double w = std::sqrt(std::max(es.eigenvalues()(k), 0.0));
    const Eigen::VectorXd v = es.eigenvectors().col(k);
    Mode md;
    md.frequency_Hz = w / kTwoPi;
    md.damping_ratio = w > 0 ? v.dot(Cm * v) / (2.0 * w * v.dot(Mm * v)) : 0.0;
    md.damped_frequency_Hz =
        md.damping_ratio < 1.0
            ? md.frequency_Hz * std::sqrt(1.0 - md.damping_ratio * md.damping_ratio)
            : 0.0;
    modes.push_back(md);
  }
  std::sort(modes.begin(), modes.end(),
            [](const Mode& a, const Mode& b) { return a.frequency_Hz < b.frequency_Hz; });
  return modes;
}

}  // namespace gmasim
