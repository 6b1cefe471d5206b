#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include "gmasim/errors.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

const std::vector<double>& TimeSeries::column(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return columns[i];
  std::string known;
  for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
  throw InputError(fmt::format("unknown quantity '{}'; recorded quantities: {}", name, known));
}

RmsPeak rms_and_peak(const std::vector<double>& v, std::size_t begin, std::size_t end) {
  RmsPeak r;
  if (end <= begin) return r;
  double ss = 0.0;
  for (std::size_t i = begin; i < end; ++i) {
    ss += v[i] * v[i];
    r.peak = std::max(r.peak, std::fabs(v[i]));
  }
  r.rms = std::sqrt(ss / static_cast<double>(end - begin));
  return r;
}

namespace {

// Samples of one monotone branch of y(I), sorted by current, for interpolation.
struct Branch {
  std::vector<double> I, y;
  // y at current i by linear interpolation; j is the first sample with I[j] >= i of the
  // previous call (std::lower_bound's answer), walked forward: the calls come with i rising.
  double at(double i, std::size_t& j) const {
    while (j < I.size() && I[j] < i) ++j;
    if (j == 0) return y.front();
    if (j == I.size()) return y.back();
    const double f = (i - I[j - 1]) / (I[j] - I[j - 1]);
    return y[j - 1] + f * (y[j] - y[j - 1]);
  }
};

}  // namespace

double hysteresis_width(const std::vector<double>& current_A, const std::vector<double>& y,
                        std::size_t begin, std::size_t end) {
  if (end <= begin + 2) return 0.0;
  // Split the period at its current extremes into the rising and the falling branch.
  // The first sample of the smallest and of the largest current (the extremes kept in
  // registers: a load through the running index per sample made this loop latency-bound).
  std::size_t imin = begin, imax = begin;
  double cmin = current_A[begin], cmax = current_A[begin];
  for (std::size_t i = begin; i < end; ++i) {
    const double c = current_A[i];
    if (c < cmin) {
      cmin = c;
      imin = i;
    }
    if (c > cmax) {
      cmax = c;
      imax = i;
    }
  }
  // The branches' storage is kept per thread: identify evaluates seven loops per candidate.
  thread_local Branch rise, fall;
  auto collect = [&](Branch& b, std::size_t from, std::size_t to, bool rising) {
    // walk cyclically from `from` to `to` within [begin, end)
    const std::size_t n = end - begin;
    const std::size_t count = (to >= from ? to - from : to + n - from) + 1;  // from .. to
    b.I.resize(count);
    b.y.resize(count);
    std::size_t k = from;
    for (std::size_t cnt = 0; cnt < count; ++cnt) {
      b.I[cnt] = current_A[k];
      b.y[cnt] = y[k];
      if (++k == end) k = begin;
    }
    if (!rising) {
      std::reverse(b.I.begin(), b.I.end());
      std::reverse(b.y.begin(), b.y.end());
    }
    // Keep a strictly increasing current sequence for interpolation.
    std::size_t w = 0;
    for (std::size_t i = 0; i < b.I.size(); ++i) {
      if (w > 0 && b.I[i] <= b.I[w - 1]) continue;
      b.I[w] = b.I[i];
      b.y[w] = b.y[i];
      ++w;
    }
    b.I.resize(w);
    b.y.resize(w);
  };
  collect(rise, imin, imax, true);
  collect(fall, imax, imin, false);
  if (rise.I.size() < 2 || fall.I.size() < 2) return 0.0;
  const double lo = std::max(rise.I.front(), fall.I.front());
  const double hi = std::min(rise.I.back(), fall.I.back());
  if (!(hi > lo)) return 0.0;
  const int grid = 2001;
  double gap = 0.0;
  std::size_t jr = 0, jf = 0;  // the grid rises: each branch is walked once
  for (int g = 0; g < grid; ++g) {
    const double i = lo + (hi - lo) * g / (grid - 1);
    gap = std::max(gap, std::fabs(rise.at(i, jr) - fall.at(i, jf)));
  }
  return gap;
}

namespace {

// Rows with t0 <= t < t1 (one whole period when t1 - t0 is the period), with a tolerance of
// 1e-9 of the window for the times accumulated in floating point.
std::pair<std::size_t, std::size_t> window_rows(const std::vector<double>& t, double t0,
                                                double t1) {
  const double eps = 1e-9 * (t1 - t0);
  const auto row = [&](double x) {
    return static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), x - eps) - t.begin());
  };
  return {row(t0), row(t1)};
}

// Peak-to-peak and mean of v over rows [b, e), e > b.
std::pair<double, double> pp_and_mean(const std::vector<double>& v, std::size_t b, std::size_t e) {
  double s = 0.0;
  for (std::size_t i = b; i < e; ++i) s += v[i];
  return {peak_to_peak(std::span<const double>(v).subspan(b, e - b)),
          s / static_cast<double>(e - b)};
}

}  // namespace

double peak_to_peak(std::span<const double> v) {
  if (v.empty()) return 0.0;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return *hi - *lo;
}

namespace {

constexpr int kRefine = 8;  // refined points per sample interval

// The cubic Hermite basis at s = j / kRefine, j < kRefine: h00, h10, h01, h11.
struct HermiteBasis {
  double h00[kRefine], h10[kRefine], h01[kRefine], h11[kRefine];
};

const HermiteBasis& hermite_basis() {
  static const HermiteBasis hb = [] {
    HermiteBasis b{};
    for (int j = 0; j < kRefine; ++j) {
      const double s = static_cast<double>(j) / kRefine, s2 = s * s, s3 = s2 * s;
      b.h00[j] = 2 * s3 - 3 * s2 + 1;
      b.h10[j] = s3 - 2 * s2 + s;
      b.h01[j] = -2 * s3 + 3 * s2;
      b.h11[j] = s3 - s2;
    }
    return b;
  }();
  return hb;
}

// Rows [b, e) of v (and the row e that closes a periodic window, when recorded) refined by
// kRefine points per sample interval with the cubic Hermite interpolant whose slopes are the
// centred differences (Catmull-Rom; third order in the sample spacing), into out (cleared
// first). The metrics of a window are then taken from the refined samples, so that the
// sampling of the extremes and the linear interpolation of the loop's branches add an error of
// third order in the step, below the integrator's second order (docs/model.md, "Time step").
void refine_window(const std::vector<double>& t, const std::vector<double>& v, std::size_t b,
                   std::size_t e, std::vector<double>& out) {
  const std::size_t last = std::min(e, t.size() - 1);  // the closing row, if any
  auto slope = [&](std::size_t k) {
    const std::size_t lo = k > 0 ? k - 1 : k, hi = k + 1 < t.size() ? k + 1 : k;
    return (v[hi] - v[lo]) / (t[hi] - t[lo]);
  };
  const HermiteBasis& hb = hermite_basis();
  const std::size_t intervals = last > b ? last - b : 0;
  out.resize(intervals * kRefine + (last < e ? 1 : 0));  // written by index: no push_back
  double* o = out.data();
  double slope_k = last > b ? slope(b) : 0.0;
  for (std::size_t k = b; k < last; ++k, o += kRefine) {
    const double h = t[k + 1] - t[k], slope_k1 = slope(k + 1);
    const double m0 = slope_k * h, m1 = slope_k1 * h, v0 = v[k], v1 = v[k + 1];
    for (int j = 0; j < kRefine; ++j)
      o[j] = hb.h00[j] * v0 + hb.h10[j] * m0 + hb.h01[j] * v1 + hb.h11[j] * m1;
    slope_k = slope_k1;
  }
  if (last < e) *o = v[last];  // no closing row: keep the last sample
}

}  // namespace

LoopMetrics loop_metrics(const std::vector<double>& t, const std::vector<double>& current_A,
                         const std::vector<double>& y_um, const std::vector<double>& B_T,
                         std::size_t b, std::size_t e, LoopMetricsWanted want) {
  thread_local std::vector<double> I, y, B;  // refined; per thread (identify: 7 per candidate)
  const double nan = std::numeric_limits<double>::quiet_NaN();
  LoopMetrics L{nan, nan, nan};
  if (want.stroke || want.hysteresis) refine_window(t, y_um, b, e, y);
  if (want.stroke) L.stroke_um = peak_to_peak(y);
  if (want.hysteresis) {
    refine_window(t, current_A, b, e, I);
    L.hysteresis_um = hysteresis_width(I, y, 0, y.size());
  }
  if (want.B_pp) {
    refine_window(t, B_T, b, e, B);
    L.B_pp_T = peak_to_peak(B);
  }
  return L;
}

Metrics compute_metrics(const TimeSeries& ts, double t0, double t1) {
  const auto& t = ts.column("t_s");
  const auto [b, e] = window_rows(t, t0, t1);
  Metrics m;
  m.window_start_s = t0;
  m.window_end_s = t1;
  if (e <= b + 2)
    throw InputError(fmt::format("metrics window [{}, {}] s holds fewer than 3 samples", t0, t1));
  const auto& y = ts.column("y_um");
  const LoopMetrics L = loop_metrics(t, ts.column("current_A"), y, ts.column("B_T"), b, e);
  m.stroke_um = L.stroke_um;
  m.hysteresis_um = L.hysteresis_um;
  m.B_pp_T = L.B_pp_T;
  m.y_mean_um = pp_and_mean(y, b, e).second;
  return m;
}

StepMetrics step_metrics(const TimeSeries& ts, double step_time_s) {
  const auto& t = ts.column("t_s");
  const auto& y = ts.column("y_um");
  StepMetrics s;
  const std::size_t n = t.size();
  std::size_t k0 = 0;  // last sample at or before the step
  while (k0 + 1 < n && t[k0 + 1] <= step_time_s) ++k0;
  if (n < k0 + 4) return s;
  s.y_initial_um = y[k0];
  const double t_end = t[n - 1];
  const double tail_from = t_end - 0.1 * (t_end - t[k0]);
  double sum = 0;
  std::size_t cnt = 0;
  for (std::size_t k = k0; k < n; ++k)
    if (t[k] >= tail_from) {
      sum += y[k];
      ++cnt;
    }
  s.y_final_um = sum / static_cast<double>(cnt);
  const double d = s.y_final_um - s.y_initial_um;
  if (!(std::fabs(d) > 1e-9)) return s;
  const double sgn = d > 0 ? 1.0 : -1.0;
  auto crossing = [&](double frac) {  // first time y passes y0 + frac d, interpolated
    const double level = s.y_initial_um + frac * d;
    for (std::size_t k = k0 + 1; k < n; ++k)
      if (sgn * (y[k] - level) >= 0.0) {
        const double a = sgn * (y[k - 1] - level), b = sgn * (y[k] - level);
        const double w = b - a > 0.0 ? -a / (b - a) : 1.0;
        return t[k - 1] + std::clamp(w, 0.0, 1.0) * (t[k] - t[k - 1]);
      }
    return std::nan("");
  };
  s.rise_time_s = crossing(0.9) - crossing(0.1);
  double over = 0.0;
  std::size_t last_out = k0;
  for (std::size_t k = k0 + 1; k < n; ++k) {
    over = std::max(over, sgn * (y[k] - s.y_final_um));
    if (std::fabs(y[k] - s.y_final_um) > 0.02 * std::fabs(d)) last_out = k;
  }
  s.overshoot_pct = over / std::fabs(d) * 100.0;
  s.settling_time_s = (last_out + 1 < n ? t[last_out + 1] : t_end) - t[k0];
  s.valid = std::isfinite(s.rise_time_s);
  return s;
}

}  // namespace gmasim

namespace gmasim {

void add_quantity_stats(Result& r, const std::vector<std::string>& names) {
  const auto& t = r.series.column("t_s");
  std::size_t b = 0, e = t.size();
  if (r.has_metrics)
    std::tie(b, e) = window_rows(t, r.metrics.window_start_s, r.metrics.window_end_s);
  for (const auto& name : names) {
    const auto& v = r.series.column(name);
    QuantityStats q;
    q.name = name;
    const RmsPeak rp = rms_and_peak(v, b, e);
    q.rms = rp.rms;
    q.peak = rp.peak;
    if (e > b) std::tie(q.pp, q.mean) = pp_and_mean(v, b, e);
    r.quantities.push_back(q);
  }
}

}  // namespace gmasim
