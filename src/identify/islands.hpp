// The islands of one rank's global search, evolved on a pool of worker threads: the number
// of islands is part of the search (it changes the result), the number of threads is not
// (it only changes how fast the same result arrives). Migration along the ring of islands
// happens between epochs, in island order, so the search is the same on every machine.
#pragma once

#include <atomic>
#include <exception>
#include <functional>
#include <memory>
#include <pagmo/algorithm.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>
#include <pagmo/types.hpp>
#include <string>
#include <vector>

#include "gmasim/identify/identify.hpp"

namespace gmasim::identify_detail {

// A seed for (rank, island, generation) from the search's seed (splitmix64's finaliser): the
// same on every machine, and distinct for every island and generation.
unsigned mix_seed(unsigned seed, int rank, int island, int generation);

// Runs f(0) .. f(n - 1) on min(threads, n) threads (the caller's among them); rethrows the
// first exception after every task has ended.
void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& f);

// Thrown by an island's fitness once a stop was requested (SIGINT/SIGTERM): the evaluation in
// progress finishes, every later one of the batch or generation throws at once, so a stop during
// the first population or a long generation takes effect within one evaluation (issue 19,
// item 4). pagmo keeps an island's population when its evolution throws.
struct SearchStopped : std::exception {
  const char* what() const noexcept override { return "the search was stopped"; }
};

// The pagmo user-defined problem: minimise the weighted RMS error [%] over u in [0, 1]^n.
// Copied into every island; the copies share only the immutable Objective. `stop` (the
// islands' copies only; null for the checkpoint's re-evaluation) makes an evaluation throw
// SearchStopped once it is set.
struct GmaProblem {
  std::shared_ptr<const Objective> obj;
  const std::atomic<bool>* stop = nullptr;

  void check_stop() const {
    if (stop && stop->load(std::memory_order_relaxed)) throw SearchStopped{};
  }
  pagmo::vector_double fitness(const pagmo::vector_double& u) const {
    check_stop();
    return {obj ? obj->rms_pct(u) : Objective::kPenalty};
  }
  std::pair<pagmo::vector_double, pagmo::vector_double> get_bounds() const {
    const std::size_t n = obj ? obj->dim() : 1;
    return {pagmo::vector_double(n, 0.0), pagmo::vector_double(n, 1.0)};
  }
  std::string get_name() const { return "gmasim identify: weighted RMS error [%]"; }
  // fitness() is const and touches no shared mutable state.
  pagmo::thread_safety get_thread_safety() const { return pagmo::thread_safety::constant; }
};

// A pagmo batch fitness evaluator over `threads` threads (the problem must be
// thread_safety::constant: its fitness is called concurrently on one object). For a
// GmaProblem, each thread's contiguous share of the points is one Objective::rms_pct_batch
// (their records in shared SIMD lanes; the same values as fitness() point by point).
struct PoolBfe {
  int threads = 1;
  pagmo::vector_double operator()(const pagmo::problem& p, const pagmo::vector_double& dvs) const;
  std::string get_name() const { return "gmasim thread pool"; }
};

struct Island {
  pagmo::algorithm algo;
  pagmo::population pop;
};

// pagmo's island semantics (an algorithm evolving a population, the best `migrants` of a
// neighbour replacing the worst if better: select_best / fair_replace) without its
// archipelago, whose thread-per-island and random choice of the neighbour made a run depend
// on the machine and the timing.
class IslandRing {
 public:
  IslandRing(int migrants, unsigned seed, int rank, int threads)
      : migrants_(migrants), seed_(seed), rank_(rank), threads_(threads < 1 ? 1 : threads) {}

  void push_back(pagmo::algorithm a, pagmo::population p);
  std::size_t size() const { return islands_.size(); }
  Island& operator[](std::size_t i) { return islands_[i]; }
  const Island& operator[](std::size_t i) const { return islands_[i]; }
  auto begin() const { return islands_.begin(); }
  auto end() const { return islands_.end(); }

  // One epoch at `generation` (the generations done before it): immigrants from the ring
  // neighbours' selections of the previous epoch, then every island's algorithm over the
  // worker threads, then each island's selection of emigrants. An island whose evolution
  // throws keeps its population and algorithm; the first exception is rethrown.
  void evolve(int generation);
  unsigned long long fevals() const;

 private:
  void immigrate(int generation);
  void emigrate(std::size_t i);

  std::vector<Island> islands_;
  std::vector<pagmo::individuals_group_t> emigrants_;  // empty before the first epoch
  int migrants_;
  unsigned seed_;
  int rank_, threads_;
};

}  // namespace gmasim::identify_detail
