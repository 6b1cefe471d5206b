#include "experiments/parallel.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {

int resolve_thread_count(int requested, std::size_t work) {
  if (requested < 0 || requested > kMaxThreads)
    throw InputError(fmt::format("threads = {} (--threads): must be 0 (all cores) or in [1, {}]",
                                 requested, kMaxThreads));
  int n = requested;
  if (n <= 0) {
    const unsigned hw = std::thread::hardware_concurrency();
    n = hw == 0 ? 1 : static_cast<int>(hw);
  }
  if (work > 0 && static_cast<std::size_t>(n) > work) n = static_cast<int>(work);
  return std::max(n, 1);
}

namespace detail {

void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& fn,
                  const ProgressFn& progress) {
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex mu;
  std::size_t done = 0;
  std::exception_ptr failure;
  auto worker = [&]() {
    for (;;) {
      if (stop.load()) return;
      const std::size_t i = next.fetch_add(1);
      if (i >= n) return;
      try {
        fn(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mu);
        if (!failure) failure = std::current_exception();
        stop.store(true);
        return;
      }
      const std::lock_guard<std::mutex> lock(mu);
      ++done;
      if (progress) progress(done, n);
    }
  };
  const int t = std::max(1, std::min<int>(threads, static_cast<int>(std::max<std::size_t>(n, 1))));
  if (t == 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(t));
    try {
      for (int k = 0; k < t; ++k) pool.emplace_back(worker);
    } catch (const std::system_error& e) {  // the system refused a thread: run with those we have
      if (pool.empty()) {
        stop.store(true);
        throw InputError(
            fmt::format("cannot start a worker thread ({}); lower --threads", e.what()));
      }
    }
    for (auto& th : pool) th.join();
  }
  if (failure) std::rethrow_exception(failure);
}

double change_pct(double a, double b) {
  if (!(std::isfinite(a) && std::isfinite(b)) || a == 0.0)
    return std::numeric_limits<double>::quiet_NaN();
  return (b - a) / a * 100.0;
}

}  // namespace detail
}  // namespace gmasim
