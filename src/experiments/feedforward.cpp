// Inverse-model feed-forward (issue 20): the stable polynomial inverse of the model's linear
// part and the quasi-static inverse of the model with its hysteresis.
// gmasim/experiments/feedforward.hpp; docs/experiments.md, "Inverse-model feed-forward".
#include "gmasim/experiments/feedforward.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>

#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim {
namespace {

// The values of a State, without its buffers' allocation (State's copy assignment reallocates
// the nodal workspace): everything quasi_static_step reads or reports. The circuit workspace
// is scratch of each solve (filled from its inputs), the energy ledgers are off.
void copy_state_values(const State& from, State& to) {
  to.t_s = from.t_s;
  to.current_A = from.current_A;
  to.y_m = from.y_m;
  to.y_stack_m = from.y_stack_m;
  to.q_m = from.q_m;
  to.z_m = from.z_m;
  to.z_v_m_per_s = from.z_v_m_per_s;
  to.B_T = from.B_T;
  std::copy(from.rods.begin(), from.rods.end(), to.rods.begin());
  std::copy(from.rod_reluctance.begin(), from.rod_reluctance.end(), to.rod_reluctance.begin());
  std::copy(from.circuit.phi.begin(), from.circuit.phi.end(), to.circuit.phi.begin());
}

// Least squares for (b1, b3) in b1 x - b3 x^3 ~ v over the points (normal equations, 2 x 2).
std::array<double, 2> odd_fit(const std::array<double, 48>& x, const std::array<double, 48>& v) {
  double s2 = 0, s4 = 0, s6 = 0, r1 = 0, r3 = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double x2 = x[k] * x[k];
    s2 += x2;
    s4 += x2 * x2;
    s6 += x2 * x2 * x2;
    r1 += x[k] * v[k];
    r3 -= x2 * x[k] * v[k];
  }
  const double det = s2 * s6 - s4 * s4;
  return {(s6 * r1 + s4 * r3) / det, (s4 * r1 + s2 * r3) / det};
}

}  // namespace

LinearInverse fit_linear_inverse(const Model& m, const Conditions& c, double bias_A,
                                 double band_Hz) {
  if (!(band_Hz > 0.0 && band_Hz <= 1e5))
    throw InputError(fmt::format(
        "feed-forward band (--feedforward-band) = {} Hz: must be in (0, 100000] Hz", band_Hz));
  const State s = settle_at_bias(m, c, bias_A, BiasState::Anhysteretic);
  const SmallSignalModel L = linearise(m, c, s);
  const std::complex<double> H0 = L.response(0.0);
  LinearInverse out;
  out.band_Hz = band_Hz;
  out.static_gain_um_per_A = std::abs(H0) * 1e6;
  if (!(std::abs(H0) > 0.0) || !std::isfinite(std::abs(H0)))
    throw InputError(fmt::format(
        "feed-forward: the model has no static gain at the bias {} A ({} um/A): nothing to invert",
        bias_A, out.static_gain_um_per_A));
  // In x = w / w_b: Re(1/H) - 1 ~ -b2 x^2 and Im(1/H) ~ b1 x - b3 x^3, a_n = b_n / w_b^n.
  const double wb = 2.0 * physics::kPi * band_Hz;
  std::array<double, 48> x{}, re{}, im{};
  std::array<std::complex<double>, 48> H{};
  for (std::size_t k = 0; k < x.size(); ++k) {
    x[k] = std::pow(10.0, -2.0 + 2.0 * static_cast<double>(k) / 47.0);
    H[k] = L.response(x[k] * band_Hz) / H0;
    const std::complex<double> z = 1.0 / H[k];
    re[k] = z.real() - 1.0;
    im[k] = z.imag();
  }
  double s4 = 0, r2 = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    s4 += x[k] * x[k] * x[k] * x[k];
    r2 -= x[k] * x[k] * re[k];
  }
  const auto [b1, b3] = odd_fit(x, im);
  out.a = {b1 / wb, r2 / s4 / (wb * wb), b3 / (wb * wb * wb)};
  for (std::size_t k = 0; k < x.size(); ++k) {
    const std::complex<double> jx(0.0, x[k]);
    const std::complex<double> P = 1.0 + b1 * jx + (r2 / s4) * jx * jx + b3 * jx * jx * jx;
    out.max_residual = std::max(out.max_residual, std::abs(P * H[k] - 1.0));
  }
  return out;
}

InverseFeedforward::InverseFeedforward(const Model& m, double temperature_C,
                                       const InverseFeedforwardSettings& s,
                                       const LinearInverse* linear)
    : m_(&m), c_(make_conditions(m, temperature_C)), set_(s) {
  if (!(s.current_limit_A > 0.0) || !std::isfinite(s.current_limit_A))
    throw InputError(
        fmt::format("feed-forward current limit {} A: must be > 0", s.current_limit_A));
  if (!(std::fabs(s.bias_A) < s.current_limit_A))
    throw InputError(fmt::format("feed-forward bias {} A: must lie inside the limit +-{} A",
                                 s.bias_A, s.current_limit_A));
  if (!(s.sample_rate_Hz > 0.0) || !std::isfinite(s.sample_rate_Hz))
    throw InputError(fmt::format("feed-forward sample rate {} Hz: must be > 0", s.sample_rate_Hz));
  if (!(s.tolerance_um > 0.0) || !std::isfinite(s.tolerance_um))
    throw InputError(fmt::format("feed-forward tolerance {} um: must be > 0", s.tolerance_um));
  lin_ = linear != nullptr ? *linear : fit_linear_inverse(m, c_, s.bias_A, s.band_Hz);
  reset();
}

void InverseFeedforward::reset() {
  shadow_ = make_state(*m_, c_, set_.bias_A);
  trial_ = shadow_;
  y_bias_m_ = shadow_.y_m;
  target_m_ = y_bias_m_;
  slope_m_per_A_ = lin_.static_gain_um_per_A * 1e-6;
  trial_current_A_ = shadow_.current_A;
  evaluations_ = 0;
}

double InverseFeedforward::output_at(double current_A) {
  copy_state_values(shadow_, trial_);
  quasi_static_step(*m_, c_, trial_, current_A);
  trial_current_A_ = current_A;
  ++evaluations_;
  return trial_.y_m;
}

// A root of y_qs(I) - target in [-limit, limit] from the last current: secant steps with the
// last good slope (y rises with I along a branch), bisection of the bracket when a step leaves
// it; the limit when even the limit falls short.
double InverseFeedforward::solve(double target_m) {
  const double lim = set_.current_limit_A, tol = set_.tolerance_um * 1e-6;
  double lo = -lim, hi = lim;
  bool lo_seen = false, hi_seen = false;  // evaluated below / above the target
  double x = shadow_.current_A, f = output_at(x) - target_m;
  for (int it = 0; it < 40 && std::fabs(f) > tol; ++it) {
    if (f < 0.0) {
      lo = x;
      lo_seen = true;
      if (x >= lim) return lim;  // the limit falls short
    } else {
      hi = x;
      hi_seen = true;
      if (x <= -lim) return -lim;
    }
    double next = x - f / slope_m_per_A_;
    if (!(next > lo && next < hi)) {
      if (lo_seen && hi_seen)
        next = 0.5 * (lo + hi);
      else
        next = f < 0.0 ? hi : lo;  // the unexplored limit
    }
    if (hi - lo <= 1e-12 * lim) break;
    const double f_next = output_at(next) - target_m;
    const double secant = (f_next - f) / (next - x);
    if (secant > 0.0 && std::isfinite(secant)) slope_m_per_A_ = secant;
    x = next;
    f = f_next;
  }
  return x;
}

double InverseFeedforward::current_A(const std::array<double, 4>& r) {
  double d = r[0];
  if (set_.dynamic) d += lin_.a[0] * r[1] + lin_.a[1] * r[2] + lin_.a[2] * r[3];
  target_m_ = y_bias_m_ + 1e-6 * d;
  evaluations_ = 0;
  const double I = solve(target_m_);
  if (trial_current_A_ != I) output_at(I);
  copy_state_values(trial_, shadow_);
  return I;
}

}  // namespace gmasim
