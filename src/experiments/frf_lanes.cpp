// The stepped-sine points of gmasim frf in SIMD lanes (frf_internal.hpp,
// stepped_sine_points_lanes): each point runs in its own lane what stepped_sine_point runs with
// run_loop -- the same grid (stepped_sine_grid), drive, and first harmonic over the measured
// periods (first_harmonic_ratio's FirstHarmonicSums, accumulated step by step). The points are
// sorted by their step count so that the lanes of a batch end close together; a lane that has ended
// idles at its last time until the batch's longest point ends.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numeric>
#include <vector>

#include "experiments/frf_internal.hpp"
#include "experiments/parallel.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/simulate/lanes.hpp"

namespace gmasim::detail {
namespace {

using cd = std::complex<double>;

struct LanePoint {
  std::size_t index = 0;  // ti * nf + fi
  double f_Hz = 0, y0_m = 0;
  SteppedSineGrid sg;
};

// One batch of points in lanes from their temperatures' bias states; Y/I into out[index].
void run_batch(const Model& m, const std::vector<Conditions>& conds, const std::vector<State>& bias,
               const FrfRequest& r, const std::vector<LanePoint>& pts, std::size_t nf,
               std::vector<cd>& out) {
  const std::size_t n = pts.size();
  std::vector<const Model*> models(n, &m);
  std::vector<const Conditions*> cs(n);
  std::vector<const State*> ss(n);
  long longest = 0;
  for (std::size_t k = 0; k < n; ++k) {
    cs[k] = &conds[pts[k].index / nf];
    ss[k] = &bias[pts[k].index / nf];
    longest = std::max(longest, pts[k].sg.grid.steps);
  }
  LaneBatch batch(models, cs, ss);
  for (std::size_t k = 0; k < n; ++k) batch.set_time(k, pts[k].sg.grid.t0_s);
  std::vector<double> current(n), dt(n), t1(n);
  std::vector<FirstHarmonicSums> sums(n);
  for (long q = 1; q <= longest; ++q) {
    for (std::size_t k = 0; k < n; ++k) {  // the Uniform clock; an ended lane idles
      const StepGrid& g = pts[k].sg.grid;
      const long kk = std::min(q, g.steps);
      t1[k] = g.t0_s + static_cast<double>(kk) * g.dt_s;
      dt[k] = g.dt_s;
      current[k] = stepped_sine_current_A(r, pts[k].f_Hz, t1[k]);
    }
    batch.step(current, dt, t1);
    for (std::size_t k = 0; k < n; ++k) {
      if (q > pts[k].sg.grid.steps) continue;
      if (batch.diverged(k))  // the point's temperature and frequency, then the run's diagnosis
        throw DivergenceError(
            stepped_sine_divergence(r, cs[k]->temperature_C, pts[k].f_Hz, batch.error(k)));
      if (q <= pts[k].sg.first) continue;
      sums[k].add(t1[k], pts[k].f_Hz, batch.y_m(k) - pts[k].y0_m, current[k] - r.bias_A);
    }
  }
  for (std::size_t k = 0; k < n; ++k) out[pts[k].index] = sums[k].ratio();
}

}  // namespace

std::vector<cd> stepped_sine_points_lanes(const Model& m, const std::vector<Conditions>& conds,
                                          const std::vector<State>& bias,
                                          const std::vector<SmallSignalModel>& lin,
                                          const FrfRequest& r, const std::vector<double>& f,
                                          int threads, const ProgressFn& progress) {
  const std::size_t nf = f.size(), n = conds.size() * nf;
  std::vector<LanePoint> pts(n);
  for (std::size_t idx = 0; idx < n; ++idx) {
    const std::size_t ti = idx / nf;
    pts[idx].index = idx;
    pts[idx].f_Hz = f[idx % nf];
    pts[idx].y0_m = lin[ti].y0_m;
    pts[idx].sg = stepped_sine_grid(lin[ti], r, f[idx % nf]);  // checks every grid first
  }
  std::stable_sort(pts.begin(), pts.end(), [](const LanePoint& a, const LanePoint& b) {
    return a.sg.grid.steps < b.sg.grid.steps;
  });
  const auto w = static_cast<std::size_t>(std::max(1, lanes_width()));
  const std::size_t batches = (n + w - 1) / w;
  std::vector<cd> out(n);
  // The longest batches first, so that the threads end together.
  parallel_for(
      batches, threads,
      [&](std::size_t b) {
        const std::size_t last = batches - 1 - b, lo = last * w, hi = std::min(n, lo + w);
        const std::vector<LanePoint> batch(pts.begin() + static_cast<std::ptrdiff_t>(lo),
                                           pts.begin() + static_cast<std::ptrdiff_t>(hi));
        run_batch(m, conds, bias, r, batch, nf, out);
      },
      progress);
  return out;
}

}  // namespace gmasim::detail
