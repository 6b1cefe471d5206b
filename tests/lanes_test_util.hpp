// Shared by the lane tests (test_lanes.cpp, test_lanes_preisach.cpp, test_lanes_rods.cpp): each
// lane of a batch against the width-1 instance of the same kernel, bit for bit.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <vector>

#include "gmasim/model/model.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim_test {

// One lane per (c[i], s[i]) of model m (the lane tests' runs).
inline gmasim::LaneBatch lane_batch(const gmasim::Model& m,
                                    const std::vector<gmasim::Conditions>& c,
                                    const std::vector<gmasim::State>& s) {
  std::vector<const gmasim::Model*> mp(c.size(), &m);
  std::vector<const gmasim::Conditions*> cp;
  std::vector<const gmasim::State*> sp;
  for (std::size_t i = 0; i < c.size(); ++i) {
    cp.push_back(&c[i]);
    sp.push_back(&s[i]);
  }
  return gmasim::LaneBatch(mp, cp, sp);
}

// n simulations of model m at rest, run i at T0_C + dT_C (i % cycle) degC, driven by currents
// A (sin wt + 0.4 sin 3wt) of 1..4 A at 50..200 Hz: the third harmonic reverses the current
// twice inside each half period (minor loops). The lane tests' runs (c, s, current, batch).
struct ReversingRuns {
  const gmasim::Model* m;
  std::vector<gmasim::Conditions> c;
  std::vector<gmasim::State> s;
  std::vector<double> amp, freq;
  ReversingRuns(const gmasim::Model& model, std::size_t n, double T0_C, double dT_C,
                std::size_t cycle)
      : m(&model) {
    for (std::size_t i = 0; i < n; ++i) {
      c.push_back(gmasim::make_conditions(model, T0_C + dT_C * static_cast<double>(i % cycle)));
      amp.push_back(1.0 + 0.5 * static_cast<double>(i % 7));
      freq.push_back(50.0 + 25.0 * static_cast<double>(i % 7));
      s.push_back(gmasim::make_state(model, c.back(), 0.0));
    }
  }
  double current(std::size_t i, double t) const {
    const double w = 6.283185307179586 * freq[i] * t;
    return amp[i] * (std::sin(w) + 0.4 * std::sin(3.0 * w));
  }
  gmasim::LaneBatch batch() const { return lane_batch(*m, c, s); }
};

// Steps every lane of two batches of runs.batch() (the second as the width-1 instance) for
// `steps` steps of dt_s with runs.current(i, t) and, every 50 steps and at the last, checks that
// numbers(state) of each lane is the same bit for bit. Runs: c (the conditions, one per lane),
// s (the states), batch(), current(i, t).
template <class Runs, class Numbers>
void expect_lanes_equal_width_one(const Runs& runs, long steps, double dt_s, Numbers numbers) {
  gmasim::LaneBatch a = runs.batch(), b = runs.batch();
  const std::size_t n = runs.c.size();
  std::vector<double> cur(n), dt(n, dt_s), t1(n);
  gmasim::State sa = runs.s[0], sb = runs.s[0];
  for (long k = 1; k <= steps; ++k) {
    const double t = static_cast<double>(k) * dt_s;
    for (std::size_t i = 0; i < n; ++i) {
      cur[i] = runs.current(i, t);
      t1[i] = t;
    }
    a.step(cur, dt, t1);
    b.step(cur, dt, t1, true);
    if (k % 50 != 0 && k != steps) continue;
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_FALSE(a.diverged(i)) << a.error(i);
      a.unpack(i, sa);
      b.unpack(i, sb);
      const std::vector<double> va = numbers(sa), vb = numbers(sb);
      ASSERT_EQ(va.size(), vb.size()) << "lane " << i << " step " << k;
      ASSERT_EQ(0, std::memcmp(va.data(), vb.data(), va.size() * sizeof(double)))
          << "lane " << i << " step " << k << " target " << gmasim::lanes_target();
    }
  }
}

// Biased-sine settings over temperatures x peak-to-peak currents [A] at f_Hz, `periods` each.
inline std::vector<gmasim::SimulationSettings> biased_sine_settings(
    std::initializer_list<double> temperatures_C, std::initializer_list<double> pp_A, double f_Hz,
    double periods) {
  std::vector<gmasim::SimulationSettings> set;
  for (double T : temperatures_C)
    for (double pp : pp_A) {
      gmasim::SimulationSettings s;
      s.temperature_C = T;
      s.waveform = gmasim::biased_sine(pp, f_Hz);
      s.periods = periods;
      set.push_back(s);
    }
  return set;
}

// simulate_lanes(m, set) against simulate(m, set[i]) per setting: no divergence, metrics, the
// same rows, and the stroke, the hysteresis (both relative to the stroke) and B p-p (relative
// to itself) within `tol`. Returns the largest relative difference.
inline double expect_simulate_lanes_matches(const gmasim::Model& m,
                                            const std::vector<gmasim::SimulationSettings>& set,
                                            double tol) {
  const std::vector<gmasim::Result> got = gmasim::simulate_lanes(m, set);
  EXPECT_EQ(got.size(), set.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(got.size(), set.size()); ++i) {
    const gmasim::Result ref = gmasim::simulate(m, set[i]);
    EXPECT_FALSE(got[i].diverged) << got[i].error;
    EXPECT_TRUE(got[i].has_metrics) << "setting " << i;
    if (got[i].diverged || !got[i].has_metrics) continue;
    EXPECT_EQ(got[i].series.rows(), ref.series.rows()) << "setting " << i;
    const double scale = std::fabs(ref.metrics.stroke_um);
    EXPECT_GT(scale, 0.0) << "setting " << i;
    auto rel = [&](double x, double r, double of) {
      const double e = std::fabs(x - r) / of;
      worst = std::max(worst, e);
      EXPECT_LE(e, tol) << "setting " << i;
    };
    rel(got[i].metrics.stroke_um, ref.metrics.stroke_um, scale);
    rel(got[i].metrics.hysteresis_um, ref.metrics.hysteresis_um, scale);
    rel(got[i].metrics.B_pp_T, ref.metrics.B_pp_T, std::fabs(ref.metrics.B_pp_T));
  }
  return worst;
}

}  // namespace gmasim_test
