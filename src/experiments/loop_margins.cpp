// The PID loop's stability margins (issue 40 item 3; gmasim/experiments/experiments.hpp,
// pid_loop_margins): the linearised plant (gmasim/mechanics/state_space.hpp) sampled as `track`
// drives it, the paper's discrete PID, their loop gain on the unit circle and the closed loop's
// poles. docs/experiments.md, "Closed-loop tracking".
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <complex>
#include <limits>
#include <unsupported/Eigen/MatrixFunctions>

#include "gmasim/experiments/experiments.hpp"

namespace gmasim {
namespace {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
using cd = std::complex<double>;

// The plant as `track` drives it, sample to sample: the current i_k is set at t_k, reached over
// the first plant step dt (step() interpolates the current linearly over a step) and held to
// t_k+1; the sensor reads y at t_k. Exactly:
//   x_k+1 = Phi x_k + (Gamma - R) i_k + R i_k-1,  y_k = C x_k  [m],
// Phi = e^{A Ts}, Gamma = int_0^Ts e^{A s} B ds, R = e^{A (Ts - dt)} int_0^dt e^{A s} B s/dt ds
// (the ramp's shortfall), from one exponential of the block matrix [[A, B, 0], [0, 0, 1/dt],
// [0, 0, 0]].
struct SampledPlant {
  Mat Phi;
  Vec G, R;
  Eigen::RowVectorXd C;
};
SampledPlant sample(const StateSpace& ss, double Ts, double dt) {
  const int n = ss.n_states;
  const Mat A = Eigen::Map<const Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(ss.A.data(), n, n);
  const Vec B = Eigen::Map<const Vec>(ss.B.data(), n);
  Mat M = Mat::Zero(n + 2, n + 2);
  M.topLeftCorner(n, n) = A;
  M.block(0, n, n, 1) = B;
  M(n, n + 1) = 1.0 / dt;
  const Mat E =
      (M * dt).exp();  // (0,n): int_0^dt e^{As} B ds; (0,n+1): int_0^dt e^{As} B (dt-s)/dt
  const Vec W = E.block(0, n, n, 1) - E.block(0, n + 1, n, 1);
  Mat Mt = Mat::Zero(n + 1, n + 1);
  Mt.topLeftCorner(n, n) = A;
  Mt.block(0, n, n, 1) = B;
  const Mat Et = (Mt * Ts).exp();
  SampledPlant p;
  p.Phi = Et.topLeftCorner(n, n);
  p.G = Et.block(0, n, n, 1);
  p.R = (A * (Ts - dt)).exp() * W;
  p.C = Eigen::Map<const Eigen::RowVectorXd>(ss.C.data(), n);
  return p;
}

}  // namespace

LoopMargins pid_loop_margins(const StateSpace& plant, const PidGains& g, double sample_rate_Hz,
                             double plant_dt_s, double amplifier_A_per_unit) {
  const double Ts = 1.0 / sample_rate_Hz;
  const SampledPlant p = sample(plant, Ts, plant_dt_s);
  const int n = plant.n_states;
  // The PID per sample at this rate (Pid's coefficients), the error in um: e = -1e6 y.
  const double a = amplifier_A_per_unit, kp = g.kp,
               ki = g.ki * g.reference_rate_Hz / sample_rate_Hz,
               kd = g.kd * sample_rate_Hz / g.reference_rate_Hz;
  LoopMargins out;
  out.temperature_C = plant.temperature_C;
  // The loop gain L(z) = a C_pid(z) 1e6 P(z), C_pid = kp + ki z/(z - 1) + kd (1 - 1/z), on z =
  // e^{j w Ts} from 0.1 Hz to the Nyquist frequency; the phase unwrapped from the low end.
  const int N = 6000;
  const double f0 = 0.1, f1 = 0.5 * sample_rate_Hz;
  auto loop_gain = [&](cd z) {
    const Eigen::VectorXcd x = (z * Eigen::MatrixXcd::Identity(n, n) - p.Phi.cast<cd>())
                                   .partialPivLu()
                                   .solve((p.G - p.R).cast<cd>() + p.R.cast<cd>() / z);
    const cd P = 1e6 * (p.C.cast<cd>() * x)(0);
    return a * (kp + ki * z / (z - 1.0) + kd * (1.0 - 1.0 / z)) * P;
  };
  double prev_phase = 0.0, prev_mag = 0.0, prev_f = 0.0, unwrap = 0.0;
  for (int k = 0; k < N; ++k) {
    const double f = f0 * std::pow(f1 / f0, static_cast<double>(k) / N);
    const cd L = loop_gain(std::polar(1.0, 2.0 * M_PI * f * Ts));
    const double mag = std::abs(L);
    double phase = std::arg(L) * 180.0 / M_PI + unwrap;
    if (k > 0) {
      while (phase - prev_phase > 180.0) phase -= 360.0, unwrap -= 360.0;
      while (phase - prev_phase < -180.0) phase += 360.0, unwrap += 360.0;
      // |L| = 1 crossings: the phase margin 180 + phase there (the smallest).
      if ((prev_mag - 1.0) * (mag - 1.0) <= 0.0 && prev_mag != mag) {
        const double t = (1.0 - prev_mag) / (mag - prev_mag);
        const double pm = 180.0 + prev_phase + t * (phase - prev_phase);
        const double pm_wrapped = pm - 360.0 * std::floor((pm + 180.0) / 360.0);
        if (pm_wrapped < out.phase_margin_deg) {
          out.phase_margin_deg = pm_wrapped;
          out.gain_crossover_Hz = prev_f + t * (f - prev_f);
        }
      }
      // Phase = -180 (mod 360) crossings: the gain margin -20 log10 |L| there (the smallest).
      const double a0 = std::floor((prev_phase + 180.0) / 360.0),
                   a1 = std::floor((phase + 180.0) / 360.0);
      if (a0 != a1) {
        const double target = 360.0 * std::max(a0, a1) - 180.0;
        const double t = (target - prev_phase) / (phase - prev_phase);
        const double gm = -20.0 * std::log10(prev_mag + t * (mag - prev_mag));
        if (gm < out.gain_margin_dB) {
          out.gain_margin_dB = gm;
          out.phase_crossover_Hz = prev_f + t * (f - prev_f);
        }
      }
    }
    prev_phase = phase;
    prev_mag = mag;
    prev_f = f;
  }
  // At the Nyquist frequency z = -1 and L is real: a negative L is a phase crossover there (the
  // sampled loop's classic limit cycle, the error flipping sign every sample).
  const cd L_nyquist = loop_gain(cd(-1.0, 0.0));
  if (L_nyquist.real() < 0.0) {
    const double gm = -20.0 * std::log10(std::abs(L_nyquist));
    if (gm < out.gain_margin_dB) {
      out.gain_margin_dB = gm;
      out.phase_crossover_Hz = f1;
    }
  }
  // The closed loop (r = 0, no clipping), state (x_k, i_k-1, S_k-1, e_k-1):
  //   e_k = -1e6 C x_k, S_k = S_k-1 + e_k, i_k = a (kp e_k + ki S_k + kd (e_k - e_k-1)).
  Mat Acl = Mat::Zero(n + 3, n + 3);
  const Eigen::RowVectorXd e_x = -1e6 * p.C;
  Eigen::RowVectorXd i_row = Eigen::RowVectorXd::Zero(n + 3);
  i_row.head(n) = a * (kp + ki + kd) * e_x;
  i_row(n + 1) = a * ki;
  i_row(n + 2) = -a * kd;
  Acl.topRows(n) = (p.G - p.R) * i_row;
  Acl.topLeftCorner(n, n) += p.Phi;
  Acl.block(0, n, n, 1) += p.R;
  Acl.row(n) = i_row;
  Acl.row(n + 1).head(n) = e_x;
  Acl(n + 1, n + 1) = 1.0;
  Acl.row(n + 2).head(n) = e_x;
  const Eigen::EigenSolver<Mat> es(Acl, false);
  for (Eigen::Index k = 0; k < es.eigenvalues().size(); ++k) {
    const double r = std::abs(es.eigenvalues()(k));
    if (r > out.spectral_radius) {
      out.spectral_radius = r;
      out.dominant_Hz = std::abs(std::arg(es.eigenvalues()(k))) / (2.0 * M_PI * Ts);
    }
  }
  out.stable = out.spectral_radius < 1.0;
  return out;
}

}  // namespace gmasim
