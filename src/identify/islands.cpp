// The islands of one rank's global search on a pool of worker threads (islands.hpp).
#include "identify/islands.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <pagmo/r_policies/fair_replace.hpp>
#include <pagmo/s_policies/select_best.hpp>
#include <thread>
#include <utility>

namespace gmasim::identify_detail {

unsigned mix_seed(unsigned seed, int rank, int island, int generation) {
  std::uint64_t z =
      (static_cast<std::uint64_t>(seed) << 32) ^ (static_cast<std::uint64_t>(rank) << 20) ^
      (static_cast<std::uint64_t>(island) << 12) ^ static_cast<std::uint64_t>(generation);
  z += 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return static_cast<unsigned>(z & 0x7fffffffU);
}

void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& f) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr first;
  std::mutex mu;
  auto work = [&]() {
    for (std::size_t k = next.fetch_add(1); k < n; k = next.fetch_add(1)) {
      try {
        f(k);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mu);
        if (!first) first = std::current_exception();
      }
    }
  };
  const std::size_t nt = std::min<std::size_t>(static_cast<std::size_t>(std::max(threads, 1)), n);
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < nt; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (first) std::rethrow_exception(first);
}

pagmo::vector_double PoolBfe::operator()(const pagmo::problem& p,
                                         const pagmo::vector_double& dvs) const {
  const std::size_t nx = p.get_nx(), nf = p.get_nf();
  const std::size_t count = nx == 0 ? 0 : dvs.size() / nx;
  pagmo::vector_double out(count * nf);
  auto point = [&](std::size_t k) {
    return pagmo::vector_double(dvs.begin() + static_cast<std::ptrdiff_t>(k * nx),
                                dvs.begin() + static_cast<std::ptrdiff_t>((k + 1) * nx));
  };
  const GmaProblem* g = p.extract<GmaProblem>();
  if (!g || !g->obj) {
    parallel_for(count, threads, [&](std::size_t k) {
      const pagmo::vector_double fk = p.fitness(point(k));  // counts the evaluation (atomically)
      std::copy(fk.begin(), fk.end(), out.begin() + static_cast<std::ptrdiff_t>(k * nf));
    });
    return out;
  }
  // Batches of at most kBatch points, at least one per thread: a stop takes effect within a
  // batch (SearchStopped, as fitness() throws it).
  constexpr std::size_t kBatch = 16;
  const std::size_t nt = static_cast<std::size_t>(std::max(threads, 1));
  const std::size_t per = std::clamp<std::size_t>((count + nt - 1) / nt, 1, kBatch);
  const std::size_t batches = (count + per - 1) / per;
  parallel_for(batches, threads, [&](std::size_t q) {  // nf is 1
    g->check_stop();
    const std::size_t b = q * per, e = std::min(count, b + per);
    std::vector<std::vector<double>> u;
    for (std::size_t k = b; k < e; ++k) u.push_back(point(k));
    const std::vector<double> f = g->obj->rms_pct_batch(u);
    std::copy(f.begin(), f.end(), out.begin() + static_cast<std::ptrdiff_t>(b));
  });
  p.increment_fevals(count);  // as p.fitness() would have counted them
  return out;
}

namespace {

pagmo::individuals_group_t individuals(const pagmo::population& pop) {
  return {pop.get_ID(), pop.get_x(), pop.get_f()};
}

// Which ring neighbour island i takes its immigrants from at this generation: the other
// island of two; of three or more, the predecessor or the successor, chosen by a hash of
// (seed, rank, island, generation) as pagmo chooses one at random.
std::size_t source_of(std::size_t i, std::size_t n, unsigned seed, int rank, int generation) {
  if (n == 2) return 1 - i;
  std::uint64_t z = (static_cast<std::uint64_t>(seed) << 32) ^
                    (static_cast<std::uint64_t>(rank) << 20) ^
                    (static_cast<std::uint64_t>(i) << 12) ^ static_cast<std::uint64_t>(generation) ^
                    0x5bd1e995ULL;
  z += 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return (z & 1U) ? (i + 1) % n : (i + n - 1) % n;
}

}  // namespace

void IslandRing::push_back(pagmo::algorithm a, pagmo::population p) {
  islands_.push_back({std::move(a), std::move(p)});
  emigrants_.emplace_back();
}

void IslandRing::immigrate(int generation) {
  const std::size_t n = islands_.size();
  if (n < 2) return;
  const pagmo::fair_replace replace{static_cast<pagmo::pop_size_t>(migrants_)};
  for (std::size_t i = 0; i < n; ++i) {
    const auto& mig = emigrants_[source_of(i, n, seed_, rank_, generation)];
    if (std::get<0>(mig).empty()) continue;
    pagmo::population& pop = islands_[i].pop;
    const pagmo::problem& prob = pop.get_problem();
    const auto merged =
        replace.replace(individuals(pop), prob.get_nx(), prob.get_nix(), prob.get_nobj(),
                        prob.get_nec(), prob.get_nic(), prob.get_c_tol(), mig);
    // The population in fair_replace's order (the algorithms see what pagmo's island gives).
    for (std::size_t k = 0; k < std::get<1>(merged).size(); ++k)
      pop.set_xf(static_cast<pagmo::pop_size_t>(k), std::get<1>(merged)[k], std::get<2>(merged)[k]);
  }
}

void IslandRing::emigrate(std::size_t i) {
  const pagmo::population& pop = islands_[i].pop;
  const pagmo::problem& prob = pop.get_problem();
  emigrants_[i] = pagmo::select_best{static_cast<pagmo::pop_size_t>(migrants_)}.select(
      individuals(pop), prob.get_nx(), prob.get_nix(), prob.get_nobj(), prob.get_nec(),
      prob.get_nic(), prob.get_c_tol());
}

void IslandRing::evolve(int generation) {
  immigrate(generation);
  std::vector<char> done(islands_.size(), 0);
  std::exception_ptr first;
  try {
    parallel_for(islands_.size(), threads_, [&](std::size_t i) {
      pagmo::algorithm algo = islands_[i].algo;
      pagmo::population evolved = algo.evolve(islands_[i].pop);
      islands_[i].pop = std::move(evolved);
      islands_[i].algo = std::move(algo);
      done[i] = 1;
    });
  } catch (...) {
    first = std::current_exception();
  }
  for (std::size_t i = 0; i < islands_.size(); ++i)
    if (done[i]) emigrate(i);
  if (first) std::rethrow_exception(first);
}

unsigned long long IslandRing::fevals() const {
  unsigned long long n = 0;
  for (const auto& isl : islands_) n += isl.pop.get_problem().get_fevals();
  return n;
}

}  // namespace gmasim::identify_detail
