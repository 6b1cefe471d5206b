// gmasim frf (Fig. 15): the stepped sine's peak refined adaptively, the small-signal limit of
// the stimulus and the markers taken from the data the figure draws. docs/experiments.md,
// "Frequency response" and "Small or large signal".
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "experiments/frf_internal.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim::detail {
namespace {

using cd = std::complex<double>;

// The vertex (u*, m*) of the parabola through (u0, m0), (u1, m1), (u2, m2), u0 < u1 < u2,
// clamped to [u0, u2].
Peak parabola_vertex(double u0, double u1, double u2, double m0, double m1, double m2) {
  const double d0 = u1 - u0, d2 = u1 - u2;
  const double num = d0 * d0 * (m1 - m2) - d2 * d2 * (m1 - m0);
  const double den = d0 * (m1 - m2) - d2 * (m1 - m0);
  double u = den != 0.0 ? u1 - 0.5 * num / den : u1;
  u = std::clamp(u, u0, u2);
  // Lagrange form of the parabola at u.
  const double m = m0 * (u - u1) * (u - u2) / ((u0 - u1) * (u0 - u2)) +
                   m1 * (u - u0) * (u - u2) / ((u1 - u0) * (u1 - u2)) +
                   m2 * (u - u0) * (u - u1) / ((u2 - u0) * (u2 - u1));
  return {std::exp(u), m};
}

// Static field gains dH_i/dI [A/m per A] of the linearisation (its response at s = 0, solved
// for the fields instead of the output).
Eigen::VectorXd static_field_gains(const SmallSignalModel& L) {
  const auto N = static_cast<Eigen::Index>(L.n);
  const auto n = static_cast<std::size_t>(L.n);
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(N, N);
  Eigen::VectorXd b(N);
  if (L.consistent) {  // l_i dH_i + sum_j S_ij A_j mu0 (1 + chi_j) dH_j = b_i dI
    for (std::size_t i = 0; i < n; ++i) {
      const auto ei = static_cast<Eigen::Index>(i);
      b(ei) = L.port_b_At_per_A[i];
      for (std::size_t j = 0; j < n; ++j)
        A(ei, static_cast<Eigen::Index>(j)) =
            L.port_S_per_H[i * n + j] * L.area_m2[j] * physics::kMu0 * (1.0 + L.chi[j]);
      A(ei, ei) += L.length_m[i];
    }
    return A.partialPivLu().solve(b);
  }
  // dH = g dI + G dM, dM = chi dH: (I - G chi) dH = g dI.
  for (std::size_t i = 0; i < n; ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    b(ei) = L.g_A_per_m_per_A[i];
    for (std::size_t j = 0; j < n; ++j)
      A(ei, static_cast<Eigen::Index>(j)) -= L.G[i * n + j] * L.chi[j];
  }
  return A.partialPivLu().solve(b);
}

}  // namespace

Peak data_peak(const std::vector<double>& f, const std::vector<double>& mag) {
  Peak best;
  for (std::size_t k = 1; k + 1 < mag.size(); ++k) {
    if (!(mag[k] > mag[k - 1] && mag[k] >= mag[k + 1]) || mag[k] <= best.mag) continue;
    best = parabola_vertex(std::log(f[k - 1]), std::log(f[k]), std::log(f[k + 1]), mag[k - 1],
                           mag[k], mag[k + 1]);
    best.mag = std::max(best.mag, mag[k]);
  }
  return best;
}

// The largest local maximum of the linearisation's |Y/I| on a fine log scan of [f_lo, f_hi].
static Peak linear_peak(const SmallSignalModel& lin, double f_lo, double f_hi) {
  constexpr std::size_t kScan = 2000;
  std::vector<double> f(kScan), mag(kScan);
  const double step = std::log(f_hi / f_lo) / static_cast<double>(kScan - 1);
  for (std::size_t k = 0; k < kScan; ++k) {
    f[k] = f_lo * std::exp(step * static_cast<double>(k));
    mag[k] = std::abs(lin.response(f[k]));
  }
  return data_peak(f, mag);
}

void refine_stepped_peak(const Model& m, const Conditions& c, const State& bias,
                         const SmallSignalModel& lin, const FrfRequest& r, SteppedCurve& curve) {
  const std::size_t n = curve.f_Hz.size();
  std::vector<double> mag(n);
  for (std::size_t k = 0; k < n; ++k) mag[k] = std::abs(curve.Y[k]);
  std::size_t kp = 0;
  for (std::size_t k = 1; k + 1 < n; ++k)
    if (mag[k] > mag[k - 1] && mag[k] >= mag[k + 1] && (kp == 0 || mag[k] > mag[kp])) kp = k;
  if (r.peak_refinements < 1) return;
  std::vector<double> fs;
  std::vector<cd> ys;
  auto eval = [&](double u) {
    fs.push_back(std::exp(u));
    ys.push_back(stepped_sine_point(m, c, bias, lin, r, fs.back()));
    return std::abs(ys.back());
  };
  // A grid too coarse for a sharp resonance can miss it altogether (its largest local maximum
  // is then another, smaller peak). The linearisation's own peak, found on a fine scan, is a
  // second candidate: one stepped point there, and its grid bracket wins if it is higher.
  const Peak lp = linear_peak(lin, r.f_min_Hz, r.f_max_Hz);
  double a = 0.0, b = 0.0;
  if (kp > 0) a = std::log(curve.f_Hz[kp - 1]), b = std::log(curve.f_Hz[kp + 1]);
  if (lp.f_Hz > curve.f_Hz.front() && lp.f_Hz < curve.f_Hz.back()) {
    const double m_lin = eval(std::log(lp.f_Hz));
    if (kp == 0 || m_lin > mag[kp]) {
      const auto hi = std::upper_bound(curve.f_Hz.begin(), curve.f_Hz.end(), lp.f_Hz);
      a = std::log(*(hi - 1)), b = std::log(*hi);
      kp = 1;
    }
  }
  if (kp == 0) return;
  // Golden section on [a, b] (the bracket's grid neighbours), maximising |Y/I|.
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = b - phi * (b - a), x2 = a + phi * (b - a);
  double m1 = eval(x1), m2 = r.peak_refinements > 1 ? eval(x2) : 0.0;
  for (int it = 2; it < r.peak_refinements; ++it) {
    if (m1 >= m2) {
      b = x2, x2 = x1, m2 = m1;
      x1 = b - phi * (b - a);
      m1 = eval(x1);
    } else {
      a = x1, x1 = x2, m1 = m2;
      x2 = a + phi * (b - a);
      m2 = eval(x2);
    }
  }
  for (std::size_t k = 0; k < fs.size(); ++k) {
    curve.f_Hz.push_back(fs[k]);
    curve.Y.push_back(ys[k]);
  }
  std::vector<std::size_t> order(curve.f_Hz.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t i, std::size_t j) { return curve.f_Hz[i] < curve.f_Hz[j]; });
  SteppedCurve sorted;
  for (std::size_t i : order) {
    if (!sorted.f_Hz.empty() && curve.f_Hz[i] == sorted.f_Hz.back()) continue;
    sorted.f_Hz.push_back(curve.f_Hz[i]);
    sorted.Y.push_back(curve.Y[i]);
  }
  curve = std::move(sorted);
}

double small_signal_limit_A(const Model& m, const SmallSignalModel& lin, const Conditions& c) {
  const Eigen::VectorXd g = static_field_gains(lin);
  double limit = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < c.rods.size() && i < static_cast<std::size_t>(g.size()); ++i) {
    const double dHdI = std::fabs(g(static_cast<Eigen::Index>(i)));
    const double reversible_A_per_m = with_magnetisation_law(
        m.options.magnetisation_law,
        [&](auto law) { return decltype(law)::reversible_field_range(c.rods[i]); });
    if (!std::isfinite(reversible_A_per_m) || !(dHdI > 0.0)) continue;
    limit = std::min(limit, kSmallSignalFraction * reversible_A_per_m / dHdI);
  }
  return limit;
}

void choose_markers(FrfCurve& cv, const Model& m, const SmallSignalModel& lin, const Conditions& c,
                    const FrfRequest& r) {
  cv.small_signal_limit_A = small_signal_limit_A(m, lin, c);
  cv.large_signal = r.stepped_sine && r.amplitude_A > cv.small_signal_limit_A;
  if (r.stepped_sine && (cv.large_signal || !r.small_signal)) {
    const Peak p = data_peak(cv.f_Hz, cv.stepped_mag_um_per_A);
    cv.first_resonance_Hz = p.f_Hz;
    cv.first_resonance_mag_um_per_A = p.mag;
    cv.bandwidth_3dB_Hz = cv.stepped_bandwidth_3dB_Hz;
    cv.reference_gain_um_per_A =
        cv.stepped_mag_um_per_A.empty() ? 0.0 : cv.stepped_mag_um_per_A.front();
    cv.markers_from = "stepped sine";
  } else {
    cv.reference_gain_um_per_A = std::abs(lin.response(r.f_min_Hz)) * 1e6;
    cv.markers_from = "linearisation";
  }
}

}  // namespace gmasim::detail
