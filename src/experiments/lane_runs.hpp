// Internal: the runs of an experiment's grid, in SIMD lanes where the model allows
// (gmasim/simulate/lanes.hpp) -- the sweep, the 20-150 degC runs, the ablation, reproduce's
// loops, sensitivity's units through them -- or one simulate() per setting.
#pragma once

#include <functional>
#include <span>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim::detail {

// simulate() of every setting of model m, each result handed to take(i, result) (from the
// worker threads; each i once: write only slot i). With `lanes` and a model lanes_supported, one
// block of settings per thread advances in SIMD lanes (simulate_lanes; a lane's numbers depend
// neither on the other lanes nor on the blocks, so neither on the thread count); otherwise one
// simulate() per setting on `threads` threads (resolved, >= 1). metrics_only: the results keep
// their metrics but no series (simulate_lanes' metrics_only in lanes, simulate_metrics_only one
// by one). progress(done, n) once per setting, serialised.
void simulate_settings(const Model& m, std::span<const SimulationSettings> settings, int threads,
                       bool lanes, bool metrics_only,
                       const std::function<void(std::size_t, Result&&)>& take,
                       const ProgressFn& progress = {});

}  // namespace gmasim::detail
