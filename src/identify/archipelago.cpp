// The global search: a ring of pagmo2 islands (islands.hpp: a fixed number of islands,
// evolved over the worker threads, migration between epochs in island order), one ring per
// MPI rank, champions passed along a ring of ranks every mpi_every generations, checkpoints
// every checkpoint_every generations.
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <pagmo/algorithm.hpp>
#include <pagmo/algorithms/cmaes.hpp>
#include <pagmo/algorithms/de.hpp>
#include <pagmo/algorithms/pso_gen.hpp>
#include <pagmo/algorithms/sade.hpp>
#include <pagmo/algorithms/sga.hpp>
#include <pagmo/bfe.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>
#include <pagmo/types.hpp>
#include <thread>
#include <utility>

#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "identify/internal.hpp"
#include "identify/islands.hpp"
#include "internal.hpp"

namespace gmasim::identify_detail {
namespace {

pagmo::algorithm make_algorithm(const std::string& name, unsigned gen, std::size_t dim,
                                unsigned seed) {
  if (name == "sga") {
    // Real-coded GA: tournament selection (size 2), simulated binary crossover (p 0.9,
    // eta 10), polynomial mutation (p 1/n, eta 20); pagmo's reinsertion keeps the best of
    // parents and offspring (elitist).
    return pagmo::algorithm{pagmo::sga(gen, 0.9, 10.0, 1.0 / static_cast<double>(dim), 20.0, 2u,
                                       "sbx", "polynomial", "tournament", seed)};
  }
  if (name == "de") return pagmo::algorithm{pagmo::de(gen, 0.8, 0.9, 2u, 1e-12, 1e-12, seed)};
  if (name == "sade") return pagmo::algorithm{pagmo::sade(gen, 2u, 1u, 1e-12, 1e-12, true, seed)};
  if (name == "cmaes") {
    return pagmo::algorithm{pagmo::cmaes(gen, -1, -1, -1, -1, 0.3, 1e-12, 1e-12, true, true, seed)};
  }
  if (name == "pso_gen") {
    // Generational particle swarm (pagmo's defaults: constriction factor variant 5, omega
    // 0.7298, eta 2.05 and 2.05, velocities up to half the box, lbest ring of 4): a generation's
    // particles are evaluated together through the batch fitness evaluator, on the island's own
    // thread (the islands run over the threads): their records share SIMD lanes
    // (Objective::rms_pct_batch), the same values as point by point.
    pagmo::pso_gen a(gen, 0.7298, 2.05, 2.05, 0.5, 5u, 2u, 4u, false, seed);
    a.set_bfe(pagmo::bfe{PoolBfe{1}});
    return pagmo::algorithm{a};
  }
  throw InputError(fmt::format("algorithm '{}': must be {}", name, island_algorithm_list()));
}

std::vector<IslandPopulation> snapshot(const IslandRing& archi,
                                       const std::vector<unsigned>& seeds) {
  std::vector<IslandPopulation> out;
  std::size_t i = 0;
  for (const auto& isl : archi) {
    const pagmo::population& pop = isl.pop;
    IslandPopulation ip;
    ip.seed = seeds[i++];
    ip.x = pop.get_x();
    for (const auto& f : pop.get_f()) ip.f.push_back(f[0]);
    out.push_back(std::move(ip));
  }
  return out;
}

// The best champion of this rank's islands, (f, u); u is `fallback` when no champion's
// fitness is below +inf.
std::pair<double, std::vector<double>> best_champion(const IslandRing& archi,
                                                     std::vector<double> fallback) {
  double f = std::numeric_limits<double>::infinity();
  std::vector<double> u = std::move(fallback);
  for (const auto& isl : archi) {
    const auto& pop = isl.pop;
    if (pop.champion_f()[0] < f) {
      f = pop.champion_f()[0];
      u = pop.champion_x();
    }
  }
  return {f, std::move(u)};
}

// The best champion over all islands and ranks (a collective call), kept in out if it
// improves on out.best_f.
void update_best(const IslandRing& archi, Collective& comm, GaOutcome& out) {
  auto [f, u] = best_champion(archi, out.best_u);
  global_best(comm, f, u);
  if (f < out.best_f) {
    out.best_f = f;
    out.best_u = u;
  }
}

// The ring of ranks (a collective call): this rank's best champion goes to the next rank,
// and the one received replaces the worst individual of island 0 if it is better.
void exchange_champions(IslandRing& archi, Collective& comm, std::size_t n) {
  const auto [f, u] = best_champion(archi, std::vector<double>(n, 0.0));
  std::vector<double> msg{f};
  msg.insert(msg.end(), u.begin(), u.end());
  const std::vector<double> in = comm.ring_shift(msg);
  pagmo::population& pop = archi[0].pop;
  const auto w = pop.worst_idx();
  if (in[0] < pop.get_f()[w][0])
    pop.set_xf(w, pagmo::vector_double(in.begin() + 1, in.end()), {in[0]});
}

// A checkpoint is not trusted (issue 8): its counts must match this run's layout, and every
// stored fitness (each island's individuals on this rank, and best_f) must be what the model
// gives at the stored point. One batch of evaluations, about one generation's cost; the
// verdict is collective, so that no rank is left waiting in a collective call.
void verify_restored(const Checkpoint& c, const pagmo::problem& prob, const IdentifyOptions& o,
                     Collective& comm, int ranks, std::size_t n, int threads) {
  auto fail = [&](const std::string& what) {
    throw InputError(located(o.resume_path, 0, fmt::format("cannot resume: {}", what)));
  };
  if (c.ranks != ranks || c.islands != o.islands || c.population != o.population ||
      c.dim != static_cast<int>(n) || c.rank_islands.size() != static_cast<std::size_t>(ranks))
    fail(
        fmt::format("the checkpoint holds {} rank(s) x {} island(s) x {} individuals of "
                    "dimension {}; this run has {} x {} x {} of dimension {}",
                    c.ranks, c.islands, c.population, c.dim, ranks, o.islands, o.population, n));
  const auto& mine = c.rank_islands[static_cast<std::size_t>(comm.rank())];
  pagmo::vector_double dvs(c.best_u.begin(), c.best_u.end());
  std::vector<double> stored{c.best_f};
  for (const auto& ip : mine)
    for (std::size_t k = 0; k < ip.x.size(); ++k) {
      dvs.insert(dvs.end(), ip.x[k].begin(), ip.x[k].end());
      stored.push_back(ip.f[k]);
    }
  const pagmo::vector_double fv = pagmo::bfe{PoolBfe{threads}}(prob, dvs);
  long bad = 0;
  std::size_t first_bad = 0;
  for (std::size_t k = 0; k < stored.size(); ++k) {
    const double tol = 1e-9 * std::max(1.0, std::fabs(fv[k]));
    if (!(std::fabs(fv[k] - stored[k]) <= tol)) {
      if (bad++ == 0) first_bad = k;
    }
  }
  const long bad_all = sum_ranks(comm, bad);
  if (bad_all > 0) {
    const std::string where =
        bad == 0 ? std::string("on another rank")
                 : fmt::format("{}: stored {:.9g}, the model gives {:.9g}",
                               first_bad == 0 ? std::string("best_f")
                                              : fmt::format("individual {}", first_bad - 1),
                               stored[first_bad], fv[first_bad]);
    fail(
        fmt::format("{} stored fitness value(s) are not what the model gives ({}); the file "
                    "was altered, or written by another build of gmasim",
                    bad_all, where));
  }
}

using Clock = std::chrono::steady_clock;

// One rank's global search: its archipelago, the seeds of its islands, and the outcome so
// far. run() is run_ga().
class GaRun {
 public:
  GaRun(const Objective& obj, const IdentifyOptions& o, Collective& comm)
      : o_(o),
        comm_(comm),
        rank_(comm.rank()),
        ranks_(comm.size()),
        n_(obj.dim()),
        threads_(o.threads > 0
                     ? o.threads
                     : std::max(1, static_cast<int>(std::thread::hardware_concurrency()))),
        fp_(fingerprints(obj, o, ranks_)),
        prob_{GmaProblem{std::make_shared<const Objective>(obj)}},
        island_prob_{GmaProblem{std::make_shared<const Objective>(obj), o.stop}} {}

  GaOutcome run(const std::vector<double>& start_u, double start_f) {
    out_.best_u = start_u;
    out_.best_f = start_f;
    // A stop while the first populations are evaluated ends the search at once, with the start
    // model as the best so far and no checkpoint (there is no generation to keep); every rank
    // leaves together.
    bool stopped = false;
    try {
      const std::vector<std::vector<IslandPopulation>> restored = resume();
      build_islands(start_u, start_f, restored);
    } catch (const SearchStopped&) {
      stopped = true;
    }
    if (any_rank(comm_, stopped)) {
      out_.interrupted = true;
      out_.wall_s = seconds_since(t_start_);
      return out_;
    }
    record_start();
    t_epoch_ = Clock::now();
    while (out_.generation < o_.generations) {
      if (run_epoch()) {
        out_.interrupted = true;
        break;
      }
    }
    out_.wall_s = seconds_since(t_start_);
    return out_;
  }

 private:
  // With o.resume_path: the outcome so far from the checkpoint (checked against this run,
  // its fitness values against the model), and every rank's islands; else nothing.
  std::vector<std::vector<IslandPopulation>> resume() {
    if (o_.resume_path.empty()) return {};
    Checkpoint c = read_checkpoint(o_.resume_path);
    check_compatible(c, fp_, o_.resume_path);
    verify_restored(c, prob_, o_, comm_, ranks_, n_, threads_);
    out_.resumed = true;
    out_.generation = c.generation;
    out_.evaluations = c.evaluations;
    wall_before_ = c.wall_s;
    if (c.best_f <= out_.best_f) {
      out_.best_f = c.best_f;
      out_.best_u = c.best_u;
    }
    out_.history = c.history;
    return std::move(c.rank_islands);
  }

  // This rank's islands on a ring, each running the algorithm for the first epoch's
  // generations.
  void build_islands(const std::vector<double>& start_u, double start_f,
                     const std::vector<std::vector<IslandPopulation>>& restored) {
    current_gen_ = static_cast<unsigned>(
        std::min(o_.migrate_every, std::max(1, o_.generations - out_.generation)));
    for (int i = 0; i < o_.islands; ++i) {
      const unsigned s = mix_seed(o_.seed, rank_, i, out_.generation);
      seeds_.push_back(s);
      pagmo::population pop = island_population(i, s, start_u, start_f, restored);
      archi_.push_back(make_algorithm(o_.algorithm, current_gen_, n_, s), std::move(pop));
    }
  }

  // Island i's population: as the checkpoint holds it, or a random one (evaluated over
  // threads) with the start model in place of island 0's worst individual.
  pagmo::population island_population(
      int i, unsigned seed, const std::vector<double>& start_u, double start_f,
      const std::vector<std::vector<IslandPopulation>>& restored) const {
    if (!out_.resumed) {
      pagmo::population pop{island_prob_, pagmo::bfe{PoolBfe{threads_}},
                            static_cast<pagmo::pop_size_t>(o_.population), seed};
      if (i == 0) pop.set_xf(pop.worst_idx(), start_u, {start_f});  // seed the start model
      return pop;
    }
    pagmo::population pop{island_prob_, 0u, seed};
    const auto& ip = restored[static_cast<std::size_t>(rank_)][static_cast<std::size_t>(i)];
    for (std::size_t k = 0; k < ip.x.size(); ++k) pop.push_back(ip.x[k], {ip.f[k]});
    return pop;
  }

  // The evaluations of the initial populations (all ranks), the best so far, and the
  // history's generation 0 (a resumed run has its counts and history from the checkpoint).
  void record_start() {
    if (!out_.resumed) {
      out_.evaluations = sum_ranks(comm_, static_cast<long>(archi_.fevals()));
      out_.run_evaluations = out_.evaluations;
    }
    update_best(archi_, comm_, out_);
    if (!out_.resumed) {
      const double wall = seconds_since(t_start_);
      out_.history.push_back({"ga", 0, out_.evaluations, out_.best_f, wall,
                              wall > 0 ? static_cast<double>(out_.evaluations) / wall : 0.0});
    }
  }

  // One epoch of up to migrate_every generations, then the champions over the ring of ranks
  // (every mpi_every generations), the best so far, the history and the checkpoint. True
  // when a stop was requested on any rank.
  bool run_epoch() {
    const int gens = std::min(o_.migrate_every, o_.generations - out_.generation);
    const int prev_gen = out_.generation;
    const long epoch_evals = evolve(gens);
    const int X = o_.mpi_every > 0 ? o_.mpi_every : o_.migrate_every;
    if (ranks_ > 1 && out_.generation / X != prev_gen / X) exchange_champions(archi_, comm_, n_);
    // Best so far over all islands and ranks.
    update_best(archi_, comm_, out_);
    record_epoch(epoch_evals);
    const bool stop = any_rank(comm_, o_.stop && o_.stop->load());
    const bool due = o_.checkpoint_every > 0 &&
                     out_.generation / o_.checkpoint_every != prev_gen / o_.checkpoint_every;
    if (!o_.checkpoint_path.empty() && (due || stop || out_.generation >= o_.generations))
      write_checkpoint();
    return stop;
  }

  // `gens` generations on every island; returns the evaluations of all ranks.
  long evolve(int gens) {
    if (static_cast<unsigned>(gens) != current_gen_) {
      int i = 0;
      for (std::size_t k = 0; k < archi_.size(); ++k) {
        archi_[k].algo = make_algorithm(o_.algorithm, static_cast<unsigned>(gens), n_,
                                        mix_seed(o_.seed, rank_, i++, out_.generation));
      }
      current_gen_ = static_cast<unsigned>(gens);
    }
    const auto before = archi_.fevals();
    bool cut = false;  // a stop cut the epoch short: its generations do not count
    try {              // each island: immigrants from its ring neighbour, `gens` generations
      archi_.evolve(out_.generation);
    } catch (const SearchStopped&) {
      cut = true;
    }
    if (!any_rank(comm_, cut)) out_.generation += gens;
    const long epoch_evals = sum_ranks(comm_, static_cast<long>(archi_.fevals() - before));
    out_.evaluations += epoch_evals;
    out_.run_evaluations += epoch_evals;
    return epoch_evals;
  }

  // The epoch's history entry, and the progress report on rank 0.
  void record_epoch(long epoch_evals) {
    const auto now = Clock::now();
    const double dt = std::chrono::duration<double>(now - t_epoch_).count();
    t_epoch_ = now;
    HistoryEntry h;
    h.phase = "ga";
    h.step = out_.generation;
    h.evaluations = out_.evaluations;
    h.best_rms_pct = out_.best_f;
    h.wall_s = wall_before_ + std::chrono::duration<double>(now - t_start_).count();
    h.evals_per_s = dt > 0 ? static_cast<double>(epoch_evals) / dt : 0.0;
    out_.history.push_back(h);
    if (rank_ == 0 && o_.progress) {
      o_.progress({"ga", out_.generation, o_.generations, "", out_.best_f, out_.evaluations,
                   h.evals_per_s, h.wall_s});
    }
  }

  // Every rank's islands, gathered to rank 0 (a collective call), which writes the file.
  void write_checkpoint() {
    const std::string block = islands_text(snapshot(archi_, seeds_));
    const auto blocks = comm_.gather(block, 0);
    if (rank_ != 0) return;
    Checkpoint c;
    c.fp = fp_;
    c.algorithm = o_.algorithm;
    c.ranks = ranks_;
    c.islands = o_.islands;
    c.population = o_.population;
    c.dim = static_cast<int>(n_);
    c.seed = o_.seed;
    c.generation = out_.generation;
    c.evaluations = out_.evaluations;
    c.wall_s = wall_before_ + seconds_since(t_start_);
    c.best_f = out_.best_f;
    c.best_u = out_.best_u;
    c.history = out_.history;
    write_file_atomic(o_.checkpoint_path, checkpoint_text(c, blocks));
  }

  const Clock::time_point t_start_ = Clock::now();
  const IdentifyOptions& o_;
  Collective& comm_;
  const int rank_, ranks_;
  const std::size_t n_;
  const int threads_;  // worker threads of the islands' evolution and the first populations
  const Fingerprints fp_;
  const pagmo::problem prob_;         // the checkpoint's re-evaluation: never stopped
  const pagmo::problem island_prob_;  // the islands': stops with o.stop
  GaOutcome out_;
  double wall_before_ = 0.0;  // GA wall time of the run(s) before a resume
  IslandRing archi_{o_.migrants, o_.seed, rank_, threads_};
  std::vector<unsigned> seeds_;
  unsigned current_gen_ = 0;  // generations per evolve() of the islands' algorithms
  Clock::time_point t_epoch_;
};

}  // namespace

GaOutcome run_ga(const Objective& obj, const IdentifyOptions& o, Collective& comm,
                 const std::vector<double>& start_u, double start_f) {
  return GaRun(obj, o, comm).run(start_u, start_f);
}

}  // namespace gmasim::identify_detail
