#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

Waveform biased_sine(double pp_A, double frequency_Hz, double min_A) {
  Waveform w;
  w.kind = WaveformKind::BiasedSine;
  w.pp_A = pp_A;
  w.frequency_Hz = frequency_Hz;
  w.min_A = min_A;
  return w;
}

double Waveform::current_at(double t) const {
  constexpr double two_pi = 2.0 * physics::kPi;
  switch (kind) {
    case WaveformKind::BiasedSine:
      return biased_sine_from_cos(std::cos(two_pi * frequency_Hz * t));
    case WaveformKind::DC:
      return level_A;
    case WaveformKind::Step:
      return t < step_time_s ? level_A : step_to_A;
    case WaveformKind::Chirp: {
      // Linear sweep: phase = 2 pi (f0 t + (f1 - f0) t^2 / (2 T)).
      const double tt = std::min(t, duration_s);
      const double phase = two_pi * (f0_Hz * tt + 0.5 * (f1_Hz - f0_Hz) * tt * tt / duration_s);
      return offset_A + amplitude_A * std::sin(phase);
    }
    case WaveformKind::Table:
      return interpolate_held(table_t_s, table_current_A, t);
  }
  return 0.0;
}

double interpolate_held(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (at <= x.front()) return y.front();
  if (at >= x.back()) return y.back();
  const auto it = std::upper_bound(x.begin(), x.end(), at);
  const auto j = static_cast<std::size_t>(it - x.begin());
  const double f = (at - x[j - 1]) / (x[j] - x[j - 1]);
  return y[j - 1] + f * (y[j] - y[j - 1]);
}

double auto_dt(const Waveform& w) {
  switch (w.kind) {
    case WaveformKind::BiasedSine:
      return std::min(kMaxDt_s, w.period_s() / kStepsPerPeriod);
    case WaveformKind::Chirp:
      return std::min(kMaxDt_s, 1.0 / (kStepsPerPeriod * std::max(w.f0_Hz, w.f1_Hz)));
    default:
      return kMaxDt_s;
  }
}

double claim_dt(const Waveform& w) {
  if (w.kind != WaveformKind::BiasedSine) return auto_dt(w);
  return std::min(kClaimMaxDt_s, w.period_s() / kStepsPerPeriod);
}

}  // namespace gmasim
