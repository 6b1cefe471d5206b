// The PID loop's stability margins (issue 40 item 3; gmasim/experiments/experiments.hpp,
// pid_loop_margins): the linearised plant (gmasim/mechanics/state_space.hpp) sampled as `track`
// drives it, the paper's discrete PID, their loop gain on the unit circle and the closed loop's
// poles. docs/experiments.md, "Closed-loop tracking".
#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <limits>

#include "gmasim/experiments/experiments.hpp"
#include "mechanics/dense.hpp"

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
  const Mat E = dense::exponential(
      M * dt);  // (0,n): int_0^dt e^{As} B ds; (0,n+1): int_0^dt e^{As} B (dt-s)/dt
  const Vec W = E.block(0, n, n, 1) - E.block(0, n + 1, n, 1);
  Mat Mt = Mat::Zero(n + 1, n + 1);
  Mt.topLeftCorner(n, n) = A;
  Mt.block(0, n, n, 1) = B;
  const Mat Et = dense::exponential(Mt * Ts);
  SampledPlant p;
  p.Phi = Et.topLeftCorner(n, n);
  p.G = Et.block(0, n, n, 1);
  p.R = dense::exponential(A * (Ts - dt)) * W;
  p.C = Eigen::Map<const Eigen::RowVectorXd>(ss.C.data(), n);
  return p;
}

// The PID per sample at its rate (Pid's coefficients), times the amplifier; the error in um.
struct SampledPid {
  double a, kp, ki, kd;
  cd at(cd z) const { return a * (kp + ki * z / (z - 1.0) + kd * (1.0 - 1.0 / z)); }
};

// The loop gain L(z) = C_pid(z) 1e6 P(z) on z = e^{j w Ts} from 0.1 Hz to the Nyquist frequency,
// the phase unwrapped from the low end: the smallest phase margin (180 + phase at |L| = 1) and
// gain margin (-20 log10 |L| where the phase crosses -180 mod 360; at z = -1, where L is real,
// when it is negative: the sampled loop's classic limit cycle).
void unit_circle_margins(const SampledPlant& p, const SampledPid& c, double Ts, LoopMargins& out) {
  const auto n = static_cast<Eigen::Index>(p.G.size());
  auto loop_gain = [&](cd z) {
    const Eigen::VectorXcd x = (z * Eigen::MatrixXcd::Identity(n, n) - p.Phi.cast<cd>())
                                   .partialPivLu()
                                   .solve((p.G - p.R).cast<cd>() + p.R.cast<cd>() / z);
    return c.at(z) * 1e6 * (p.C.cast<cd>() * x)(0);
  };
  const int N = 1500;
  const double f0 = 0.1, f1 = 0.5 / Ts;
  double prev_phase = 0.0, prev_mag = 0.0, prev_f = 0.0, unwrap = 0.0;
  for (int k = 0; k < N; ++k) {
    const double f = f0 * std::pow(f1 / f0, static_cast<double>(k) / N);
    const cd L = loop_gain(std::polar(1.0, 2.0 * M_PI * f * Ts));
    const double mag = std::abs(L);
    double phase = std::arg(L) * 180.0 / M_PI + unwrap;
    if (k > 0) {
      while (phase - prev_phase > 180.0) phase -= 360.0, unwrap -= 360.0;
      while (phase - prev_phase < -180.0) phase += 360.0, unwrap += 360.0;
      if ((prev_mag - 1.0) * (mag - 1.0) <= 0.0 && prev_mag != mag) {  // |L| = 1
        const double t = (1.0 - prev_mag) / (mag - prev_mag);
        const double pm = 180.0 + prev_phase + t * (phase - prev_phase);
        const double pm_wrapped = pm - 360.0 * std::floor((pm + 180.0) / 360.0);
        if (pm_wrapped < out.phase_margin_deg) {
          out.phase_margin_deg = pm_wrapped;
          out.gain_crossover_Hz = prev_f + t * (f - prev_f);
        }
      }
      const double a0 = std::floor((prev_phase + 180.0) / 360.0),
                   a1 = std::floor((phase + 180.0) / 360.0);
      if (a0 != a1) {  // phase = -180 (mod 360)
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
  const cd L_nyquist = loop_gain(cd(-1.0, 0.0));
  const double gm = -20.0 * std::log10(std::abs(L_nyquist));
  if (L_nyquist.real() < 0.0 && gm < out.gain_margin_dB) {
    out.gain_margin_dB = gm;
    out.phase_crossover_Hz = f1;
  }
}

// The closed loop (r = 0, no clipping), state (x_k, i_k-1, S_k-1, e_k-1):
//   e_k = -1e6 C x_k, S_k = S_k-1 + e_k, i_k = a (kp e_k + ki S_k + kd (e_k - e_k-1));
// its largest pole magnitude and that pole's frequency.
void closed_loop_poles(const SampledPlant& p, const SampledPid& c, double Ts, LoopMargins& out) {
  const auto n = static_cast<Eigen::Index>(p.G.size());
  Mat Acl = Mat::Zero(n + 3, n + 3);
  const Eigen::RowVectorXd e_x = -1e6 * p.C;
  Eigen::RowVectorXd i_row = Eigen::RowVectorXd::Zero(n + 3);
  i_row.head(n) = c.a * (c.kp + c.ki + c.kd) * e_x;
  i_row(n + 1) = c.a * c.ki;
  i_row(n + 2) = -c.a * c.kd;
  Acl.topRows(n) = (p.G - p.R) * i_row;
  Acl.topLeftCorner(n, n) += p.Phi;
  Acl.block(0, n, n, 1) += p.R;
  Acl.row(n) = i_row;
  Acl.row(n + 1).head(n) = e_x;
  Acl(n + 1, n + 1) = 1.0;
  Acl.row(n + 2).head(n) = e_x;
  for (const cd& z : dense::eigenvalues(Acl)) {
    const double r = std::abs(z);
    if (r > out.spectral_radius) {
      out.spectral_radius = r;
      out.dominant_Hz = std::abs(std::arg(z)) / (2.0 * M_PI * Ts);
    }
  }
  out.stable = out.spectral_radius < 1.0;
}

}  // namespace

LoopMargins pid_loop_margins(const StateSpace& plant, const PidGains& g, double sample_rate_Hz,
                             double plant_dt_s, double amplifier_A_per_unit) {
  const double Ts = 1.0 / sample_rate_Hz;
  const SampledPlant p = sample(plant, Ts, plant_dt_s);
  const Pid::PerSample k = Pid::per_sample(g, sample_rate_Hz);
  const SampledPid c{amplifier_A_per_unit, k.kp, k.ki, k.kd};
  LoopMargins out;
  out.temperature_C = plant.temperature_C;
  unit_circle_margins(p, c, Ts, out);
  closed_loop_poles(p, c, Ts, out);
  return out;
}

}  // namespace gmasim
