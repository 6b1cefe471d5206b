// The global search: a pagmo2 archipelago of thread islands (one thread per island) on a
// ring topology, one archipelago per MPI rank, champions passed along a ring of ranks every
// mpi_every generations, checkpoints every checkpoint_every generations.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <pagmo/algorithm.hpp>
#include <pagmo/algorithms/cmaes.hpp>
#include <pagmo/algorithms/de.hpp>
#include <pagmo/algorithms/sade.hpp>
#include <pagmo/algorithms/sga.hpp>
#include <pagmo/archipelago.hpp>
#include <pagmo/batch_evaluators/thread_bfe.hpp>
#include <pagmo/bfe.hpp>
#include <pagmo/island.hpp>
#include <pagmo/islands/thread_island.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>
#include <pagmo/r_policies/fair_replace.hpp>
#include <pagmo/s_policies/select_best.hpp>
#include <pagmo/topologies/ring.hpp>
#include <pagmo/topology.hpp>
#include <pagmo/types.hpp>

#include "gmasim/errors.hpp"
#include "gmasim/io.hpp"
#include "internal.hpp"

namespace gmasim::identify_detail {
namespace {

// The pagmo user-defined problem: minimise the weighted RMS error [%] over u in [0, 1]^n.
// Copied into every island; the copies share only the immutable Objective.
struct GmaProblem {
  std::shared_ptr<const Objective> obj;

  pagmo::vector_double fitness(const pagmo::vector_double& u) const {
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
  throw InputError(fmt::format("algorithm '{}': must be sga, de, sade or cmaes", name));
}

std::vector<IslandPopulation> snapshot(const pagmo::archipelago& archi,
                                       const std::vector<unsigned>& seeds) {
  std::vector<IslandPopulation> out;
  std::size_t i = 0;
  for (const auto& isl : archi) {
    const pagmo::population pop = isl.get_population();
    IslandPopulation ip;
    ip.seed = seeds[i++];
    ip.x = pop.get_x();
    for (const auto& f : pop.get_f()) ip.f.push_back(f[0]);
    out.push_back(std::move(ip));
  }
  return out;
}

unsigned long long fevals(const pagmo::archipelago& archi) {
  unsigned long long n = 0;
  for (const auto& isl : archi) n += isl.get_population().get_problem().get_fevals();
  return n;
}

// The best champion over all islands and ranks (a collective call), kept in out if it
// improves on out.best_f.
void update_best(const pagmo::archipelago& archi, Collective& comm, GaOutcome& out) {
  double f = std::numeric_limits<double>::infinity();
  std::vector<double> u = out.best_u;
  for (const auto& isl : archi) {
    const auto pop = isl.get_population();
    if (pop.champion_f()[0] < f) {
      f = pop.champion_f()[0];
      u = pop.champion_x();
    }
  }
  global_best(comm, f, u);
  if (f < out.best_f) {
    out.best_f = f;
    out.best_u = u;
  }
}

// A checkpoint is not trusted (issue 8): its counts must match this run's layout, and every
// stored fitness (each island's individuals on this rank, and best_f) must be what the model
// gives at the stored point. One batch of evaluations, about one generation's cost; the
// verdict is collective, so that no rank is left waiting in a collective call.
void verify_restored(const Checkpoint& c, const pagmo::problem& prob, const IdentifyOptions& o,
                     Collective& comm, int ranks, std::size_t n) {
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
  const pagmo::vector_double fv = pagmo::bfe{pagmo::thread_bfe{}}(prob, dvs);
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

}  // namespace

GaOutcome run_ga(const Objective& obj, const IdentifyOptions& o, Collective& comm,
                 const std::vector<double>& start_u, double start_f) {
  using clock = std::chrono::steady_clock;
  const auto t_start = clock::now();
  const int rank = comm.rank(), ranks = comm.size();
  const std::size_t n = obj.dim();
  const auto P = static_cast<pagmo::pop_size_t>(o.population);
  const int K = o.migrate_every;
  const int X = o.mpi_every > 0 ? o.mpi_every : o.migrate_every;
  const Fingerprints fp = fingerprints(obj, o, ranks);
  const pagmo::problem prob{GmaProblem{std::make_shared<const Objective>(obj)}};

  GaOutcome out;
  out.best_u = start_u;
  out.best_f = start_f;
  double wall_before = 0.0;  // GA wall time of the run(s) before a resume
  std::vector<std::vector<IslandPopulation>> restored;
  if (!o.resume_path.empty()) {
    Checkpoint c = read_checkpoint(o.resume_path);
    check_compatible(c, fp, o.resume_path);
    verify_restored(c, prob, o, comm, ranks, n);
    out.resumed = true;
    out.generation = c.generation;
    out.evaluations = c.evaluations;
    wall_before = c.wall_s;
    if (c.best_f <= out.best_f) {
      out.best_f = c.best_f;
      out.best_u = c.best_u;
    }
    out.history = c.history;
    restored = std::move(c.rank_islands);
  }

  // ---- the archipelago of this rank --------------------------------------------------
  pagmo::archipelago archi{pagmo::topology{pagmo::ring{}}};
  std::vector<unsigned> seeds;
  const auto migrants = static_cast<pagmo::pop_size_t>(o.migrants);
  const unsigned first_gen =
      static_cast<unsigned>(std::min(K, std::max(1, o.generations - out.generation)));
  for (int i = 0; i < o.islands; ++i) {
    const unsigned s = mix_seed(o.seed, rank, i, out.generation);
    seeds.push_back(s);
    pagmo::population pop{prob, 0u, s};
    if (out.resumed) {
      const auto& ip = restored[static_cast<std::size_t>(rank)][static_cast<std::size_t>(i)];
      for (std::size_t k = 0; k < ip.x.size(); ++k) pop.push_back(ip.x[k], {ip.f[k]});
    } else {
      pop = pagmo::population{prob, pagmo::bfe{pagmo::thread_bfe{}}, P, s};
      if (i == 0) pop.set_xf(pop.worst_idx(), start_u, {start_f});  // seed the start model
    }
    archi.push_back(pagmo::thread_island{}, make_algorithm(o.algorithm, first_gen, n, s), pop,
                    pagmo::fair_replace{migrants}, pagmo::select_best{migrants});
  }
  if (!out.resumed) {
    out.evaluations = sum_ranks(comm, static_cast<long>(fevals(archi)));
    out.run_evaluations = out.evaluations;
  }
  update_best(archi, comm, out);
  if (!out.resumed) {
    const double wall = std::chrono::duration<double>(clock::now() - t_start).count();
    out.history.push_back({"ga", 0, out.evaluations, out.best_f, wall,
                           wall > 0 ? static_cast<double>(out.evaluations) / wall : 0.0});
  }

  auto write_checkpoint = [&]() {
    const std::string block = islands_text(snapshot(archi, seeds));
    const auto blocks = comm.gather(block, 0);
    if (rank != 0) return;
    Checkpoint c;
    c.fp_parameters = fp.parameters;
    c.fp_data = fp.data;
    c.fp_settings = fp.settings;
    c.fp_layout = fp.layout;
    c.algorithm = o.algorithm;
    c.ranks = ranks;
    c.islands = o.islands;
    c.population = o.population;
    c.dim = static_cast<int>(n);
    c.seed = o.seed;
    c.generation = out.generation;
    c.evaluations = out.evaluations;
    c.wall_s = wall_before + std::chrono::duration<double>(clock::now() - t_start).count();
    c.best_f = out.best_f;
    c.best_u = out.best_u;
    c.history = out.history;
    write_file_atomic(o.checkpoint_path, checkpoint_text(c, blocks));
  };

  // ---- epochs of K generations ---------------------------------------------------------
  unsigned current_gen = first_gen;
  auto t_epoch = clock::now();
  while (out.generation < o.generations) {
    const int gens = std::min(K, o.generations - out.generation);
    if (static_cast<unsigned>(gens) != current_gen) {
      int i = 0;
      for (auto& isl : archi) {
        isl.set_algorithm(make_algorithm(o.algorithm, static_cast<unsigned>(gens), n,
                                         mix_seed(o.seed, rank, i++, out.generation)));
      }
      current_gen = static_cast<unsigned>(gens);
    }
    const auto before = fevals(archi);
    archi.evolve(1);  // each island: immigrants from its ring neighbour, `gens` generations
    archi.wait_check();
    const int prev_gen = out.generation;
    out.generation += gens;
    const long epoch_evals = sum_ranks(comm, static_cast<long>(fevals(archi) - before));
    out.evaluations += epoch_evals;
    out.run_evaluations += epoch_evals;

    // Champions over the ring of ranks.
    if (ranks > 1 && out.generation / X != prev_gen / X) {
      double f = std::numeric_limits<double>::infinity();
      std::vector<double> u(n, 0.0);
      for (const auto& isl : archi) {
        const auto pop = isl.get_population();
        if (pop.champion_f()[0] < f) {
          f = pop.champion_f()[0];
          u = pop.champion_x();
        }
      }
      std::vector<double> msg{f};
      msg.insert(msg.end(), u.begin(), u.end());
      const std::vector<double> in = comm.ring_shift(msg);
      auto& isl = *archi.begin();
      pagmo::population pop = isl.get_population();
      const auto w = pop.worst_idx();
      if (in[0] < pop.get_f()[w][0]) {
        pop.set_xf(w, pagmo::vector_double(in.begin() + 1, in.end()), {in[0]});
        isl.set_population(pop);
      }
    }
    // Best so far over all islands and ranks.
    update_best(archi, comm, out);
    const auto now = clock::now();
    const double dt = std::chrono::duration<double>(now - t_epoch).count();
    t_epoch = now;
    HistoryEntry h;
    h.phase = "ga";
    h.step = out.generation;
    h.evaluations = out.evaluations;
    h.best_rms_pct = out.best_f;
    h.wall_s = wall_before + std::chrono::duration<double>(now - t_start).count();
    h.evals_per_s = dt > 0 ? static_cast<double>(epoch_evals) / dt : 0.0;
    out.history.push_back(h);
    if (rank == 0 && o.progress) {
      o.progress({"ga", out.generation, o.generations, out.best_f, out.evaluations, h.evals_per_s,
                  h.wall_s});
    }
    const bool stop = any_rank(comm, o.stop && o.stop->load());
    const bool due = o.checkpoint_every > 0 &&
                     out.generation / o.checkpoint_every != prev_gen / o.checkpoint_every;
    if (!o.checkpoint_path.empty() && (due || stop || out.generation >= o.generations))
      write_checkpoint();
    if (stop) {
      out.interrupted = true;
      break;
    }
  }
  out.wall_s = std::chrono::duration<double>(clock::now() - t_start).count();
  return out;
}

}  // namespace gmasim::identify_detail
