#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include "gmasim/errors.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "simulate/record.hpp"

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

// One branch of a loop, walked sample by sample: the samples from `from` on, `count` of them,
// cyclically within [begin, end), forward (the rising branch) or backward (the falling one, so
// that its current rises too); of them, those whose current exceeds the last kept one are kept
// (a strictly increasing current sequence). at(i) is y at current i by linear interpolation
// between the first kept sample with current >= i and the one before it (the first kept
// sample's y below the branch, the last kept one's above it); the calls come with i rising.
// Nothing is copied: the kept samples are found as the queries reach them.
class BranchWalk {
 public:
  BranchWalk(const double* I, const double* y, std::size_t begin, std::size_t end, std::size_t from,
             std::size_t count, bool forward)
      : I_(I), y_(y), begin_(begin), end_(end), k_(from), left_(count), forward_(forward) {
    cur_I_ = I_[k_];
    cur_y_ = first_y_ = y_[k_];
    step();
  }
  double at(double i) {
    while (!exhausted_ && cur_I_ < i) advance();
    if (!moved_) return first_y_;
    if (exhausted_) return cur_y_;
    const double f = (i - prev_I_) / (cur_I_ - prev_I_);
    return prev_y_ + f * (cur_y_ - prev_y_);
  }
  // The number of kept samples (up to 2) and the current of the last one: a walk of its own
  // (hysteresis_width's currents with a NaN, where the branch's ends are not its extremes).
  std::pair<std::size_t, double> kept_and_last() {
    std::size_t kept = 1;
    while (!exhausted_) {
      advance();
      if (!exhausted_) kept = std::min<std::size_t>(kept + 1, 2);
    }
    return {kept, cur_I_};
  }

 private:
  void step() {
    --left_;
    if (forward_) {
      if (++k_ == end_) k_ = begin_;
    } else {
      k_ = k_ == begin_ ? end_ - 1 : k_ - 1;
    }
  }
  // To the next kept sample; exhausted (past the last kept one) when there is none.
  void advance() {
    moved_ = true;
    while (left_ > 0) {
      const double c = I_[k_];
      const std::size_t k = k_;
      step();
      if (c <= cur_I_) continue;
      prev_I_ = cur_I_;
      prev_y_ = cur_y_;
      cur_I_ = c;
      cur_y_ = y_[k];
      return;
    }
    exhausted_ = true;
  }

  const double *I_, *y_;
  std::size_t begin_, end_, k_, left_;
  bool forward_, moved_ = false, exhausted_ = false;
  double first_y_ = 0, prev_I_ = 0, prev_y_ = 0, cur_I_ = 0, cur_y_ = 0;
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
  bool nan = false;
  for (std::size_t i = begin; i < end; ++i) {
    const double c = current_A[i];
    nan = nan || c != c;
    if (c < cmin) {
      cmin = c;
      imin = i;
    }
    if (c > cmax) {
      cmax = c;
      imax = i;
    }
  }
  // The rising branch from imin to imax, the falling one from imax to imin (walked back from
  // imin), cyclically within [begin, end).
  const std::size_t n = end - begin;
  auto count = [n](std::size_t from, std::size_t to) {
    return (to >= from ? to - from : to + n - from) + 1;
  };
  const double* I = current_A.data();
  BranchWalk rise(I, y.data(), begin, end, imin, count(imin, imax), true);
  BranchWalk fall(I, y.data(), begin, end, imin, count(imax, imin), false);
  // Both branches start at cmin; with finite currents each keeps cmax last (both hold imax), so
  // each keeps two samples or more where cmax > cmin. With a NaN, each branch is walked once
  // for its kept samples and its last one.
  double lo = cmin, hi = cmax;
  bool two = cmax > cmin;
  if (nan) {
    const auto [kr, last_r] = BranchWalk(rise).kept_and_last();
    const auto [kf, last_f] = BranchWalk(fall).kept_and_last();
    two = kr >= 2 && kf >= 2;
    hi = std::min(last_r, last_f);
  }
  if (!two || !(hi > lo)) return 0.0;
  const int grid = 2001;
  double gap = 0.0;
  for (int g = 0; g < grid; ++g) {  // the grid rises: each branch is walked once
    const double i = lo + (hi - lo) * g / (grid - 1);
    gap = std::max(gap, std::fabs(rise.at(i) - fall.at(i)));
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

// peak_to_peak of refine_window(t, v, b, e)'s samples without storing them, the same bits: the
// refined values are computed only in the intervals that can hold an extreme, by the same
// expression and in the same order. A cubic Hermite segment lies within max(v0, v1) + 4/27
// (|m0| + |m1|) and min(v0, v1) - 4/27 (|m0| + |m1|) (h00, h01 >= 0, h00 + h01 = 1, |h10|,
// |h11| <= 4/27), so an interval whose bounds (4/27 rounded up to 0.15, and 1e-12 of the terms
// for the rounding) stay strictly within the extremes of the refined samples at the nodes
// (v[k] itself) holds neither. Where a value or a slope is not finite, the stored refinement.
double refined_peak_to_peak(const std::vector<double>& t, const std::vector<double>& v,
                            std::size_t b, std::size_t e, std::vector<double>& scratch) {
  const std::size_t last = std::min(e, t.size() - 1);
  const std::size_t nodes = (last > b ? last - b : 0) + (last < e ? 1 : 0);
  if (nodes == 0) return 0.0;
  double node_lo = v[b], node_hi = v[b];
  bool finite = true;
  for (std::size_t k = b; k < b + nodes; ++k) {
    node_lo = std::min(node_lo, v[k]);
    node_hi = std::max(node_hi, v[k]);
    finite = finite && std::isfinite(v[k]);
  }
  auto stored = [&] {
    refine_window(t, v, b, e, scratch);
    return peak_to_peak(scratch);
  };
  if (!finite) return stored();
  auto slope = [&](std::size_t k) {
    const std::size_t lo = k > 0 ? k - 1 : k, hi = k + 1 < t.size() ? k + 1 : k;
    return (v[hi] - v[lo]) / (t[hi] - t[lo]);
  };
  // std::minmax_element's extremes: the first smallest, the last largest
  double lo = 0.0, hi = 0.0;
  bool any = false;
  auto take = [&](double x) {
    if (!any) {
      lo = hi = x;
      any = true;
      return;
    }
    if (x < lo) lo = x;
    if (!(x < hi)) hi = x;
  };
  const HermiteBasis& hb = hermite_basis();
  double slope_k = last > b ? slope(b) : 0.0;
  for (std::size_t k = b; k < last; ++k) {
    const double h = t[k + 1] - t[k], slope_k1 = slope(k + 1);
    const double m0 = slope_k * h, m1 = slope_k1 * h, v0 = v[k], v1 = v[k + 1];
    slope_k = slope_k1;
    const double am = std::fabs(m0) + std::fabs(m1);
    const double reach = 0.15 * am + 1e-12 * (std::fabs(v0) + std::fabs(v1) + am);
    if (!std::isfinite(reach + v1)) return stored();
    if (std::max(v0, v1) + reach < node_hi && std::min(v0, v1) - reach > node_lo) continue;
    for (int j = 0; j < kRefine; ++j)
      take(hb.h00[j] * v0 + hb.h10[j] * m0 + hb.h01[j] * v1 + hb.h11[j] * m1);
  }
  if (last < e) take(v[last]);  // no closing row: the last sample
  return hi - lo;
}

}  // namespace

LoopMetrics loop_metrics(const std::vector<double>& t, const std::vector<double>& current_A,
                         const std::vector<double>& y_um, const std::vector<double>& B_T,
                         std::size_t b, std::size_t e, LoopMetricsWanted want) {
  thread_local std::vector<double> I, y;  // refined; per thread (identify: 7 per candidate)
  const double nan = std::numeric_limits<double>::quiet_NaN();
  LoopMetrics L{nan, nan, nan};
  if (want.hysteresis) {  // the refined y stored once, for the stroke too
    refine_window(t, y_um, b, e, y);
    if (want.stroke) L.stroke_um = peak_to_peak(y);
    refine_window(t, current_A, b, e, I);
    L.hysteresis_um = hysteresis_width(I, y, 0, y.size());
  } else if (want.stroke) {
    L.stroke_um = refined_peak_to_peak(t, y_um, b, e, y);
  }
  if (want.B_pp) L.B_pp_T = refined_peak_to_peak(t, B_T, b, e, I);
  return L;
}

Metrics compute_metrics(const TimeSeries& ts, double t0, double t1) {
  return compute_metrics(ts.column("t_s"), ts.column("current_A"), ts.column("y_um"),
                         ts.column("B_T"), t0, t1);
}

Metrics compute_metrics(const std::vector<double>& t, const std::vector<double>& current_A,
                        const std::vector<double>& y, const std::vector<double>& B_T, double t0,
                        double t1) {
  const auto [b, e] = window_rows(t, t0, t1);
  Metrics m;
  m.window_start_s = t0;
  m.window_end_s = t1;
  if (e <= b + 2)
    throw InputError(fmt::format("metrics window [{}, {}] s holds fewer than 3 samples", t0, t1));
  const LoopMetrics L = loop_metrics(t, current_A, y, B_T, b, e);
  m.stroke_um = L.stroke_um;
  m.hysteresis_um = L.hysteresis_um;
  m.B_pp_T = L.B_pp_T;
  double sum = 0.0;  // pp_and_mean's mean
  for (std::size_t i = b; i < e; ++i) sum += y[i];
  m.y_mean_um = sum / static_cast<double>(e - b);
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
