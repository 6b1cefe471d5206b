// Shared by the lane tests (test_lanes.cpp, test_lanes_preisach.cpp): each lane of a batch
// against the width-1 instance of the same kernel, bit for bit.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "gmasim/model/model.hpp"
#include "gmasim/simulate/lanes.hpp"

namespace gmasim_test {

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

}  // namespace gmasim_test
