// Internal: searches in lock step, their runs batched in SIMD lanes (lockstep.hpp).
#include "lockstep.hpp"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "experiments/lane_runs.hpp"
#include "experiments/parallel.hpp"
#include "gmasim/simulate/lanes.hpp"

namespace gmasim::detail {
namespace {

// The runs the searches of one group wait on; the last search to wait (or to leave while the
// others wait) runs the batch on its own thread.
class Batcher {
 public:
  Batcher(const Model& m, int threads, std::size_t searches)
      : m_(m), threads_(threads), live_(searches), got_(searches), ready_(searches, 0) {}

  Result run(std::size_t i, const SimulationSettings& s) {
    std::unique_lock<std::mutex> lk(mu_);
    who_.push_back(i);
    want_.push_back(s);
    ready_[i] = 0;
    if (who_.size() == live_)
      run_batch(lk);
    else
      cv_.wait(lk, [&] { return ready_[i] != 0; });
    if (error_) std::rethrow_exception(error_);
    return std::move(got_[i]);
  }
  void leave() {
    std::unique_lock<std::mutex> lk(mu_);
    --live_;
    if (live_ > 0 && who_.size() == live_) run_batch(lk);
  }

 private:
  // Every live search waits here, so none touches the queue while the batch runs unlocked.
  void run_batch(std::unique_lock<std::mutex>& lk) {
    const std::vector<std::size_t> who = std::move(who_);
    const std::vector<SimulationSettings> want = std::move(want_);
    who_.clear();
    want_.clear();
    lk.unlock();
    std::exception_ptr err;
    try {
      simulate_settings(m_, want, threads_, true, true,
                        [&](std::size_t k, Result&& r) { got_[who[k]] = std::move(r); });
    } catch (...) {
      err = std::current_exception();
    }
    lk.lock();
    if (err && !error_) error_ = err;
    for (std::size_t i : who) ready_[i] = 1;
    cv_.notify_all();
  }

  const Model& m_;
  const int threads_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::size_t live_;
  std::vector<std::size_t> who_;
  std::vector<SimulationSettings> want_;
  std::vector<Result> got_;
  std::vector<char> ready_;
  std::exception_ptr error_;
};

}  // namespace

void lockstep_searches(const Model& m, std::size_t n, int threads, bool lanes,
                       const std::function<void(std::size_t, const RunFn&)>& search,
                       const ProgressFn& progress) {
  if (!(lanes && lanes_supported(m))) {
    const RunFn one = [&](const SimulationSettings& s) { return simulate(m, s); };
    parallel_for(
        n, threads, [&](std::size_t i) { search(i, one); }, progress);
    return;
  }
  std::mutex mu;  // progress and the first error
  std::size_t done = 0;
  std::exception_ptr first;
  for (std::size_t g0 = 0; g0 < n; g0 += kLockstepSearches) {
    const std::size_t g1 = std::min(n, g0 + kLockstepSearches);
    Batcher batch(m, threads, g1 - g0);
    std::vector<std::thread> pool;
    for (std::size_t i = g0; i < g1; ++i)
      pool.emplace_back([&, i] {
        const RunFn run = [&](const SimulationSettings& s) { return batch.run(i - g0, s); };
        try {
          search(i, run);
        } catch (...) {
          const std::lock_guard<std::mutex> lock(mu);
          if (!first) first = std::current_exception();
        }
        batch.leave();
        if (!progress) return;
        const std::lock_guard<std::mutex> lock(mu);
        progress(++done, n);
      });
    for (auto& t : pool) t.join();
    if (first) std::rethrow_exception(first);
  }
}

}  // namespace gmasim::detail
