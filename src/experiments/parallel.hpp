// Internal: the work-list runner shared by the experiments. A fixed list of n items; N
// std::threads take indices from an atomic counter; each item writes only its own slot,
// so the result does not depend on the thread count or on scheduling.
#pragma once

#include <cstddef>
#include <functional>

#include "gmasim/experiments/experiments.hpp"

namespace gmasim::detail {

// Runs fn(i) for every i in [0, n) on `threads` threads (already resolved, >= 1).
// progress(done, n) is called after each item, serialised by a mutex. The first
// exception thrown by fn stops the remaining items and is rethrown after every thread has
// joined.
void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& fn,
                  const ProgressFn& progress);

// (b - a) / a in percent; NaN when a is 0 or either value is not finite.
double change_pct(double a, double b);

}  // namespace gmasim::detail
