// The frequency response's markers (Fig. 15): the first resonance and the -3 dB bandwidth of a
// magnitude curve, and the linearisation's markers on run_frf's dense log grid, read where the
// markers' rules look (linear_frf_markers). docs/experiments.md, "Frequency response".
#include <algorithm>
#include <cmath>
#include <vector>

#include "experiments/frf_internal.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/mechanics/mechanics.hpp"
#include "gmasim/physics/magnetic.hpp"

namespace gmasim {
namespace {

// find_resonance_Hz's local maximum at k, refined by the parabola through k - 1, k, k + 1 in
// log f.
double parabola_peak_Hz(const std::vector<double>& f, const std::vector<double>& mag,
                        std::size_t k) {
  const double a = mag[k - 1], b = mag[k], cc = mag[k + 1];
  const double den = a - 2 * b + cc;
  const double off = den != 0.0 ? 0.5 * (a - cc) / den : 0.0;
  const double lf = std::log(f[k]) + off * 0.5 * (std::log(f[k + 1]) - std::log(f[k - 1]));
  return std::exp(lf);
}

// find_bandwidth_3dB_Hz's crossing of level between k - 1 and k, interpolated in log f.
double crossing_Hz(const std::vector<double>& f, const std::vector<double>& mag, std::size_t k,
                   double level) {
  const double u = (mag[k - 1] - level) / (mag[k - 1] - mag[k]);
  return std::exp(std::log(f[k - 1]) + u * (std::log(f[k]) - std::log(f[k - 1])));
}

bool local_max(const std::vector<double>& mag, std::size_t k) {
  return mag[k] > mag[k - 1] && mag[k] >= mag[k + 1];
}

// linear_frf_markers's grid: kDense points over the band; the coarse scan reads every
// kCoarse-th of them.
constexpr int kDense = 4000;
constexpr std::size_t kCoarse = 8;

// |Y| on the dense grid f, computed on demand (each point at most once).
struct LazyMagnitudes {
  const SmallSignalModel& lin;
  const std::vector<double>& f;
  std::vector<double> mag;
  std::vector<char> done;
  LazyMagnitudes(const SmallSignalModel& l, const std::vector<double>& fd)
      : lin(l), f(fd), mag(fd.size(), 0.0), done(fd.size(), 0) {}
  double at(std::size_t k) {
    if (!done[k]) mag[k] = std::abs(lin.response(f[k])), done[k] = 1;
    return mag[k];
  }
  void fill(std::size_t lo, std::size_t hi) {  // [lo, hi], clamped to the grid
    for (std::size_t k = lo; k <= std::min(hi, f.size() - 1); ++k) (void)at(k);
  }
  bool known(std::size_t k) const { return done[k] != 0; }
};

// The dense grid index nearest f_Hz (log grid of n points over [f.front(), f.back()]), or n
// when f_Hz is outside the band or not finite.
std::size_t grid_index(const std::vector<double>& f, double f_Hz) {
  const double u = std::log(f_Hz / f.front()) / std::log(f.back() / f.front());
  if (!(u >= 0.0 && u <= 1.0)) return f.size();
  return static_cast<std::size_t>(std::lround(u * static_cast<double>(f.size() - 1)));
}

// The undamped natural frequencies of the linearisation's oscillators (eq. 15's diagonal and
// the sensor mount) [Hz]: where a resonance and its antiresonance can be sharper than the
// coarse scan.
std::vector<double> natural_frequencies_Hz(const SmallSignalModel& lin) {
  std::vector<double> fn;
  for (std::size_t i = 0; i < lin.mass_kg.size(); ++i)
    fn.push_back(std::sqrt(lin.stiffness_N_per_m[i] / lin.mass_kg[i]) / (2.0 * physics::kPi));
  if (lin.sensor_mount)
    fn.push_back(std::sqrt(lin.sm_stiffness_N_per_m / lin.sm_mass_kg) / (2.0 * physics::kPi));
  return fn;
}

}  // namespace

std::vector<double> detail::log_grid(double f0, double f1, int n) {
  std::vector<double> f(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k)
    f[static_cast<std::size_t>(k)] = f0 * std::pow(f1 / f0, static_cast<double>(k) / (n - 1));
  return f;
}

double find_resonance_Hz(const std::vector<double>& f, const std::vector<double>& mag) {
  if (mag.size() < 3) return 0.0;
  double best = 0.0, f_best = 0.0;
  for (std::size_t k = 1; k + 1 < mag.size(); ++k) {
    if (local_max(mag, k) && mag[k] > best) {
      best = mag[k];
      f_best = parabola_peak_Hz(f, mag, k);
    }
  }
  return f_best;
}

double find_bandwidth_3dB_Hz(const std::vector<double>& f, const std::vector<double>& mag) {
  if (mag.size() < 2) return 0.0;
  const double level = mag.front() / std::sqrt(2.0);
  for (std::size_t k = 1; k < mag.size(); ++k)
    if (mag[k] < level) return crossing_Hz(f, mag, k, level);
  return 0.0;
}

// find_resonance_Hz and find_bandwidth_3dB_Hz of |Y| on the dense grid, reading the dense points
// only where those rules can pick one: a coarse scan (every kCoarse-th point), then the dense
// points around each coarse local maximum (the peak), each coarse local minimum before the
// coarse curve first falls below the level (a notch that may cross it first), the first coarse
// interval that crosses it, and each oscillator's natural frequency (a resonance sharper than
// the coarse scan). The markers are those of the dense curve whenever its largest peak and its
// first crossing lie in those windows, which holds unless a peak or a notch is narrower than
// the coarse spacing away from every natural frequency (tests/test_frf_markers.cpp).
LinearFrfMarkers linear_frf_markers(const SmallSignalModel& lin, double f_min_Hz, double f_max_Hz) {
  // The grid of the last band asked for on this thread (identify asks for the same band in
  // every evaluation: 4000 std::pow saved each time).
  thread_local double band[2] = {0.0, 0.0};
  thread_local std::vector<double> fd;
  if (fd.empty() || band[0] != f_min_Hz || band[1] != f_max_Hz) {
    fd = detail::log_grid(f_min_Hz, f_max_Hz, kDense);
    band[0] = f_min_Hz;
    band[1] = f_max_Hz;
  }
  const std::size_t n = fd.size(), w = kCoarse;
  LazyMagnitudes y(lin, fd);
  std::vector<std::size_t> coarse;
  for (std::size_t k = 0; k < n; k += w) coarse.push_back(k);
  if (coarse.back() != n - 1) coarse.push_back(n - 1);
  for (std::size_t k : coarse) (void)y.at(k);
  const double level = y.at(0) / std::sqrt(2.0);
  bool crossed = false;
  for (std::size_t j = 0; j < coarse.size(); ++j) {
    const double mj = y.at(coarse[j]);
    const double lo = j > 0 ? y.at(coarse[j - 1]) : mj;
    const double hi = j + 1 < coarse.size() ? y.at(coarse[j + 1]) : mj;
    const std::size_t from = j > 0 ? coarse[j - 1] : 0;
    const std::size_t to = j + 1 < coarse.size() ? coarse[j + 1] : n - 1;
    if (mj >= lo && mj >= hi) y.fill(from, to);              // a peak's window
    if (!crossed && mj <= lo && mj <= hi) y.fill(from, to);  // a notch's window
    if (!crossed && mj < level) y.fill(from, coarse[j]), crossed = true;
  }
  for (double fn : natural_frequencies_Hz(lin)) {
    const std::size_t k = grid_index(fd, fn);
    if (k < n) y.fill(k > 2 * w ? k - 2 * w : 0, k + 2 * w);
  }
  LinearFrfMarkers lm;
  double best = 0.0;
  for (std::size_t k = 1; k + 1 < n; ++k) {
    if (!(y.known(k - 1) && y.known(k) && y.known(k + 1))) continue;
    if (local_max(y.mag, k) && y.mag[k] > best) {
      best = y.mag[k];
      lm.first_resonance_Hz = parabola_peak_Hz(fd, y.mag, k);
    }
  }
  for (std::size_t k = 1; k < n; ++k) {
    if (!y.known(k) || !(y.mag[k] < level)) continue;
    while (!y.known(k - 1) && y.at(k - 1) < level) --k;  // the run below the level from its start
    lm.bandwidth_3dB_Hz = crossing_Hz(fd, y.mag, k, level);
    break;
  }
  return lm;
}

}  // namespace gmasim
