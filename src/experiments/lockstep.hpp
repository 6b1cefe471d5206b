// Internal: searches that ask for one run at a time (compensate's root finders) advancing in
// SIMD lanes together, in lock step.
#pragma once

#include <cstddef>
#include <functional>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim::detail {

// What a search calls for a run: simulate() of the settings (metrics only, in lanes).
using RunFn = std::function<Result(const SimulationSettings&)>;

// Runs search(i, run) for every i in [0, n). With `lanes` and a model lanes_supported, each
// search runs on its own thread (at most kLockstepSearches at a time) and blocks in run();
// whenever every unfinished search waits on a run, the waiting runs advance together in SIMD
// lanes (lane_runs.hpp: metrics only, on `threads` threads), one run of each search per batch.
// A lane's numbers do not depend on the other lanes, so a search's path depends neither on
// the others nor on the thread count. Otherwise run() is simulate() and the searches take
// `threads` threads (parallel_for). progress(done, n) after each search. The first exception
// of a search is rethrown after all have ended.
inline constexpr std::size_t kLockstepSearches = 64;
void lockstep_searches(const Model& m, std::size_t n, int threads, bool lanes,
                       const std::function<void(std::size_t, const RunFn&)>& search,
                       const ProgressFn& progress);

}  // namespace gmasim::detail
