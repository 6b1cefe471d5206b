// The loop metrics (src/simulate/metrics.cpp) against their plain form: the refined window
// stored, its peak-to-peak by std::minmax_element, the hysteresis branches copied, reversed and
// filtered before they are interpolated (as metrics.cpp computed them before the refined
// peak-to-peak skipped the intervals that hold no extreme and the branches were walked in
// place). Same inputs, the same bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/simulate.hpp"

using namespace gmasim;

namespace {

// metrics.cpp's refine_window: 8 cubic Hermite points per interval, centred slopes.
std::vector<double> refined(const std::vector<double>& t, const std::vector<double>& v,
                            std::size_t b, std::size_t e) {
  const std::size_t last = std::min(e, t.size() - 1);
  auto slope = [&](std::size_t k) {
    const std::size_t lo = k > 0 ? k - 1 : k, hi = k + 1 < t.size() ? k + 1 : k;
    return (v[hi] - v[lo]) / (t[hi] - t[lo]);
  };
  std::vector<double> out;
  for (std::size_t k = b; k < last; ++k) {
    const double h = t[k + 1] - t[k], m0 = slope(k) * h, m1 = slope(k + 1) * h;
    for (int j = 0; j < 8; ++j) {
      const double s = j / 8.0, s2 = s * s, s3 = s2 * s;
      out.push_back((2 * s3 - 3 * s2 + 1) * v[k] + (s3 - 2 * s2 + s) * m0 +
                    (-2 * s3 + 3 * s2) * v[k + 1] + (s3 - s2) * m1);
    }
  }
  if (last < e) out.push_back(v[last]);
  return out;
}

double plain_pp(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return *hi - *lo;
}

// The branches copied (rising: imin .. imax; falling: imax .. imin, reversed), each filtered to a
// strictly increasing current, interpolated on 2001 currents over their overlap.
double plain_hysteresis(const std::vector<double>& I, const std::vector<double>& y) {
  const std::size_t n = I.size();
  if (n <= 2) return 0.0;
  std::size_t imin = 0, imax = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (I[i] < I[imin]) imin = i;
    if (I[i] > I[imax]) imax = i;
  }
  struct Branch {
    std::vector<double> I, y;
  };
  auto collect = [&](std::size_t from, std::size_t to, bool rising) {
    Branch b;
    for (std::size_t k = from, c = 0; c < (to >= from ? to - from : to + n - from) + 1; ++c) {
      b.I.push_back(I[k]);
      b.y.push_back(y[k]);
      k = k + 1 == n ? 0 : k + 1;
    }
    if (!rising) {
      std::reverse(b.I.begin(), b.I.end());
      std::reverse(b.y.begin(), b.y.end());
    }
    Branch kept;
    for (std::size_t i = 0; i < b.I.size(); ++i) {
      if (!kept.I.empty() && b.I[i] <= kept.I.back()) continue;
      kept.I.push_back(b.I[i]);
      kept.y.push_back(b.y[i]);
    }
    return kept;
  };
  const Branch rise = collect(imin, imax, true), fall = collect(imax, imin, false);
  if (rise.I.size() < 2 || fall.I.size() < 2) return 0.0;
  const double lo = std::max(rise.I.front(), fall.I.front());
  const double hi = std::min(rise.I.back(), fall.I.back());
  if (!(hi > lo)) return 0.0;
  // the first kept sample with I >= i, walked forward (the grid rises)
  auto at = [](const Branch& b, double i, std::size_t& j) {
    while (j < b.I.size() && b.I[j] < i) ++j;
    if (j == 0) return b.y.front();
    if (j == b.I.size()) return b.y.back();
    const double f = (i - b.I[j - 1]) / (b.I[j] - b.I[j - 1]);
    return b.y[j - 1] + f * (b.y[j] - b.y[j - 1]);
  };
  double gap = 0.0;
  std::size_t jr = 0, jf = 0;
  for (int g = 0; g < 2001; ++g) {
    const double i = lo + (hi - lo) * g / (2001 - 1);
    gap = std::max(gap, std::fabs(at(rise, i, jr) - at(fall, i, jf)));
  }
  return gap;
}

// A sweep-like period: a biased sine current, y lagging it with a harmonic and a little noise,
// B in phase; `rows` samples and a closing row.
struct Window {
  std::vector<double> t, I, y, B;
};
Window loop_window(std::size_t rows, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> z(0.0, 1.0);
  Window w;
  for (std::size_t k = 0; k <= rows + 1; ++k) {
    const double ph = 2 * physics::kPi * (static_cast<double>(k) - 1.0) / static_cast<double>(rows);
    w.t.push_back(1e-5 * static_cast<double>(k));
    w.I.push_back(3.0 * (1.0 - std::cos(ph)));
    w.y.push_back(20.0 - 15.0 * std::cos(ph - 0.2) + 1.5 * std::sin(2 * ph) + noise * z(rng));
    w.B.push_back(0.4 - 0.3 * std::cos(ph - 0.05) + 1e-3 * noise * z(rng));
  }
  return w;
}

}  // namespace

TEST(Metrics, LoopMetricsEqualTheirPlainForm) {
  int checks = 0;
  for (const double noise : {0.0, 1e-3, 0.3})
    for (const std::size_t rows : {5u, 64u, 1000u, 10000u})
      for (const bool closing : {true, false}) {
        const Window w = loop_window(rows, noise, static_cast<unsigned>(rows));
        // rows [1, 1 + rows) with the closing row 1 + rows, or without it (the series ends)
        Window c = w;
        if (!closing) {
          for (auto* v : {&c.t, &c.I, &c.y, &c.B}) v->pop_back();
        }
        const std::size_t b = 1, e = 1 + rows;
        const LoopMetrics L = loop_metrics(c.t, c.I, c.y, c.B, b, e);
        const std::vector<double> y = refined(c.t, c.y, b, e), I = refined(c.t, c.I, b, e);
        EXPECT_EQ(L.stroke_um, plain_pp(y)) << rows << " " << noise << " " << closing;
        EXPECT_EQ(L.B_pp_T, plain_pp(refined(c.t, c.B, b, e))) << rows << " " << noise;
        EXPECT_EQ(L.hysteresis_um, plain_hysteresis(I, y)) << rows << " " << noise;
        // The stroke alone (no hysteresis: the refined y is not stored, refined_peak_to_peak)
        const LoopMetrics S = loop_metrics(c.t, c.I, c.y, c.B, b, e, {true, false, false});
        EXPECT_EQ(S.stroke_um, plain_pp(y)) << rows << " " << noise << " " << closing;
        checks += 4;
      }
  EXPECT_EQ(checks, 96);
}

TEST(Metrics, HysteresisWidthEqualsItsPlainFormOnRoughLoops) {
  // Random walks (many local extremes, repeated currents, a flat stretch), and currents with a
  // NaN, where the branches' ends are not their extremes.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = 3 + static_cast<std::size_t>(trial) % 97;
    std::vector<double> I(n), y(n);
    for (std::size_t k = 0; k < n; ++k) {
      I[k] = std::round(4.0 * std::sin(0.3 * static_cast<double>(k)) + 2.0 * u(rng));
      y[k] = u(rng);
    }
    if (trial % 5 == 0) I[static_cast<std::size_t>(trial) % n] = std::nan("");
    if (trial % 7 == 0) std::fill(I.begin(), I.end(), 1.0);
    const double got = hysteresis_width(I, y, 0, n), want = plain_hysteresis(I, y);
    EXPECT_TRUE(got == want || (std::isnan(got) && std::isnan(want)))
        << trial << ": " << got << " vs " << want;
  }
}

TEST(Metrics, RefinedPeakToPeakFallsBackWhereASampleIsNotFinite) {
  Window w = loop_window(200, 0.0, 1);
  w.B[50] = std::numeric_limits<double>::infinity();
  w.y[60] = std::nan("");
  const LoopMetrics L = loop_metrics(w.t, w.I, w.y, w.B, 1, 201);
  const LoopMetrics S = loop_metrics(w.t, w.I, w.y, w.B, 1, 201, {true, false, false});
  const double B_pp = plain_pp(refined(w.t, w.B, 1, 201));
  const double stroke = plain_pp(refined(w.t, w.y, 1, 201));
  EXPECT_TRUE(L.B_pp_T == B_pp || (std::isnan(L.B_pp_T) && std::isnan(B_pp)));
  EXPECT_TRUE(L.stroke_um == stroke || (std::isnan(L.stroke_um) && std::isnan(stroke)));
  EXPECT_TRUE(S.stroke_um == stroke || (std::isnan(S.stroke_um) && std::isnan(stroke)));
}
