// Internal: an experiment's runs in SIMD lanes or one by one (lane_runs.hpp).
#include "lane_runs.hpp"

#include <algorithm>
#include <mutex>
#include <vector>

#include "experiments/parallel.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "simulate/record.hpp"

namespace gmasim::detail {

void simulate_settings(const Model& m, std::span<const SimulationSettings> settings, int threads,
                       bool lanes, bool metrics_only,
                       const std::function<void(std::size_t, Result&&)>& take,
                       const ProgressFn& progress) {
  const std::size_t n = settings.size();
  if (!(lanes && lanes_supported(m))) {
    parallel_for(
        n, threads,
        [&](std::size_t i) {
          take(i, metrics_only ? simulate_metrics_only(m, settings[i]) : simulate(m, settings[i]));
        },
        progress);
    return;
  }
  const std::size_t blocks = std::max<std::size_t>(1, std::min<std::size_t>(threads, n));
  const std::size_t per = (n + blocks - 1) / blocks;
  std::mutex mu;  // the progress callback, once per setting, serialised
  std::size_t done = 0;
  parallel_for(
      blocks, static_cast<int>(blocks),
      [&](std::size_t b) {
        const std::size_t i0 = std::min(n, b * per), i1 = std::min(n, i0 + per);
        std::vector<Result> runs = simulate_lanes(m, settings.subspan(i0, i1 - i0), metrics_only);
        for (std::size_t i = i0; i < i1; ++i) take(i, std::move(runs[i - i0]));
        if (!progress) return;
        const std::lock_guard<std::mutex> lock(mu);
        for (std::size_t i = i0; i < i1; ++i) progress(++done, n);
      },
      nullptr);
}

}  // namespace gmasim::detail
