// The multi-objective search of gmasim design (gmasim/identify/design.hpp, nsga2_search): one
// NSGA-II population (pagmo2), evolved a generation at a time with a seed of its own per
// generation, its offspring evaluated in one batch shared over the ranks and threads, and a
// checkpoint after every generation. Constraints by domination (Deb 2000): every objective of an
// infeasible point is kInfeasible plus its violation, so any feasible point dominates it, and of
// two infeasible points the smaller violation dominates.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <pagmo/algorithm.hpp>
#include <pagmo/algorithms/nsga2.hpp>
#include <pagmo/bfe.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>
#include <pagmo/types.hpp>
#include <pagmo/utils/multi_objective.hpp>
#include <random>
#include <sstream>

#include "common/text_io.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/identify/design.hpp"
#include "gmasim/io/io.hpp"
#include "identify/checkpoint_text.hpp"
#include "identify/communicator.hpp"
#include "identify/islands.hpp"

namespace gmasim {
namespace {

using identify_detail::LineReader;
using identify_detail::numbers;

constexpr const char* kMagic = "gmasim-design-checkpoint";
constexpr double kInfeasible = 1e15;  // far above any objective a design reports

// A seed per generation from the search's seed (identify's mix_seed, rank 0, island 0):
// generation g's NSGA-II is the same whether the search started at 0 or resumed at g.
unsigned generation_seed(unsigned seed, int generation) {
  return identify_detail::mix_seed(seed, 0, 0, generation);
}

// Shares a batch of candidates over the ranks (candidate i on rank i mod N) and each rank's over
// its threads, then sums the ranks' rows: every rank ends with every candidate's numbers.
struct BatchContext {
  std::size_t dim = 0, nobj = 0, width = 0;
  const std::function<std::vector<double>(const std::vector<double>&)>* evaluate = nullptr;
  int threads = 1;
  Communicator* comm = nullptr;
  long evaluations = 0;

  std::vector<std::vector<double>> run(const std::vector<std::vector<double>>& xs) {
    const std::size_t n = xs.size();
    const int rank = comm ? comm->rank() : 0, ranks = comm ? comm->size() : 1;
    std::vector<std::size_t> mine;
    for (std::size_t i = static_cast<std::size_t>(rank); i < n;
         i += static_cast<std::size_t>(ranks))
      mine.push_back(i);
    std::vector<double> flat(n * width, 0.0);
    identify_detail::parallel_for(mine.size(), threads, [&](std::size_t k) {
      const std::size_t i = mine[k];
      const std::vector<double> v = (*evaluate)(xs[i]);
      if (v.size() != width)
        throw std::logic_error(
            fmt::format("design evaluator gave {} numbers, not {}", v.size(), width));
      std::copy(v.begin(), v.end(), flat.begin() + static_cast<std::ptrdiff_t>(i * width));
    });
    if (ranks > 1) identify_detail::collective(*comm).allreduce_sum(flat.data(), flat.size());
    std::vector<std::vector<double>> out(n);
    for (std::size_t i = 0; i < n; ++i) {
      out[i].assign(flat.begin() + static_cast<std::ptrdiff_t>(i * width),
                    flat.begin() + static_cast<std::ptrdiff_t>((i + 1) * width));
      for (double& v : out[i]) v += 0.0;  // -0 -> +0, as the sum over ranks makes it
    }
    evaluations += static_cast<long>(n);
    return out;
  }

  // The objectives pagmo sees: an infeasible point's are all kInfeasible + its violation.
  std::vector<double> fitness(const std::vector<double>& v) const {
    const double viol = v[nobj];
    if (viol > 0.0 || !(viol == viol)) {
      const double f = kInfeasible + (std::isfinite(viol) ? viol : 1e12);
      return std::vector<double>(nobj, f);
    }
    std::vector<double> f(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(nobj));
    for (double& x : f)
      if (!std::isfinite(x)) x = kInfeasible;
    return f;
  }
};

// The evaluations of the last batch, by decision vector: NSGA-II keeps the survivors' fitness,
// the search keeps their full rows (values) beside them.
struct Archive {
  std::vector<std::vector<double>> x, values;
  void add(const std::vector<std::vector<double>>& xs, const std::vector<std::vector<double>>& vs) {
    x.insert(x.end(), xs.begin(), xs.end());
    values.insert(values.end(), vs.begin(), vs.end());
  }
  const std::vector<double>& find(const std::vector<double>& xi) const {
    for (std::size_t i = x.size(); i-- > 0;)
      if (x[i] == xi) return values[i];
    throw std::logic_error("design search: a survivor that was never evaluated");
  }
};

struct DesignUdp {
  std::vector<double> lower{0.0}, upper{1.0};
  std::size_t nobj = 2;
  // Only the batch evaluator evaluates (fitness is never called with it set).
  pagmo::vector_double fitness(const pagmo::vector_double&) const {
    throw std::logic_error("design search: fitness without the batch evaluator");
  }
  std::pair<pagmo::vector_double, pagmo::vector_double> get_bounds() const {
    return {lower, upper};
  }
  pagmo::vector_double::size_type get_nobj() const { return nobj; }
  std::string get_name() const { return "gmasim design"; }
};

struct DesignBfe {
  BatchContext* ctx = nullptr;
  Archive* archive = nullptr;
  pagmo::vector_double operator()(const pagmo::problem&, const pagmo::vector_double& dvs) const {
    const std::size_t n = dvs.size() / ctx->dim;
    std::vector<std::vector<double>> xs(n);
    for (std::size_t i = 0; i < n; ++i)
      xs[i].assign(dvs.begin() + static_cast<std::ptrdiff_t>(i * ctx->dim),
                   dvs.begin() + static_cast<std::ptrdiff_t>((i + 1) * ctx->dim));
    const auto vs = ctx->run(xs);
    archive->add(xs, vs);
    pagmo::vector_double f;
    for (const auto& v : vs) {
      const auto fi = ctx->fitness(v);
      f.insert(f.end(), fi.begin(), fi.end());
    }
    return f;
  }
  std::string get_name() const { return "gmasim design ranks x threads"; }
};

struct Snapshot {
  int generation = 0;
  long evaluations = 0;
  std::vector<std::vector<double>> x, values;
};

std::string checkpoint_text(const Nsga2Settings& s, std::size_t dim, std::size_t width,
                            const Snapshot& snap) {
  std::string t =
      fmt::format("{} 1\nfingerprint {}\n", kMagic, identify_detail::fnv_hex(s.fingerprint));
  t += fmt::format("layout {} {} {} {}\nseed {}\ngeneration {}\nevaluations {}\n", dim, width,
                   s.population, s.generations, s.seed, snap.generation, snap.evaluations);
  for (std::size_t i = 0; i < snap.x.size(); ++i)
    t += fmt::format("x {}\nv {}\n", numbers(snap.x[i]), numbers(snap.values[i]));
  return t + "end\n";
}

Snapshot read_checkpoint(const Nsga2Settings& s, std::size_t dim, std::size_t width) {
  const std::string text = io_detail::read_text_file(s.checkpoint_path, "design checkpoint",
                                                     io_detail::OnReadError::KeepPartial);
  LineReader in{s.checkpoint_path, {}, 0};
  std::istringstream ss(text);
  for (std::string l; std::getline(ss, l);) in.lines.push_back(l);
  if (in.next() != fmt::format("{} 1", kMagic))
    in.fail("not a gmasim design checkpoint (version 1)");
  auto cannot = [&](const std::string& what) {
    throw InputError(located(s.checkpoint_path, static_cast<long>(in.pos),
                             fmt::format("cannot resume: the checkpoint was written for {}; "
                                         "resume with the same model, variables, objectives, "
                                         "constraints, drive and search flags",
                                         what)));
  };
  if (in.expect("fingerprint") != identify_detail::fnv_hex(s.fingerprint))
    cannot("another problem");
  const auto layout = in.nums(in.expect("layout"), 4);
  if (layout[0] != static_cast<double>(dim) || layout[1] != static_cast<double>(width) ||
      layout[2] != static_cast<double>(s.population))
    cannot("another number of variables, quantities or population");
  if (in.integer("seed", 0, 4294967295.0) != static_cast<long>(s.seed)) cannot("another --seed");
  Snapshot snap;
  snap.generation = static_cast<int>(in.integer("generation", 0, 1e9));
  snap.evaluations = in.integer("evaluations", 0, 1e15);
  for (int i = 0; i < s.population; ++i) {
    snap.x.push_back(in.nums(in.expect("x"), dim));
    snap.values.push_back(in.nums(in.expect("v"), width));
  }
  if (in.next() != "end") in.fail("missing 'end' line");
  while (in.pos < in.lines.size())
    if (in.lines[in.pos++].find_first_not_of(" \t\r") != std::string::npos)
      in.fail("text after the 'end' line: resume from a checkpoint gmasim wrote whole");
  return snap;
}

// The first population: uniform in the bounds from the search's seed (generation 0's).
std::vector<std::vector<double>> first_population(const std::vector<double>& lo,
                                                  const std::vector<double>& hi, int n,
                                                  unsigned seed) {
  std::mt19937_64 rng(generation_seed(seed, 0));
  std::vector<std::vector<double>> xs(static_cast<std::size_t>(n), std::vector<double>(lo.size()));
  for (auto& x : xs)
    for (std::size_t k = 0; k < lo.size(); ++k) {
      const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;  // [0, 1), exact
      x[k] = lo[k] + u * (hi[k] - lo[k]);
    }
  return xs;
}

}  // namespace

std::vector<std::size_t> feasible_front(const std::vector<std::vector<double>>& values,
                                        std::size_t nobj) {
  std::vector<std::size_t> feas;
  for (std::size_t i = 0; i < values.size(); ++i) {
    bool ok = values[i][nobj] == 0.0;
    for (std::size_t k = 0; k < nobj && ok; ++k) ok = std::isfinite(values[i][k]);
    if (ok) feas.push_back(i);
  }
  std::vector<std::size_t> front;
  for (std::size_t i : feas) {
    bool dominated = false;
    for (std::size_t j : feas) {
      if (j == i) continue;
      bool no_worse = true, better = false;
      for (std::size_t k = 0; k < nobj; ++k) {
        no_worse = no_worse && values[j][k] <= values[i][k];
        better = better || values[j][k] < values[i][k];
      }
      if (no_worse && better) {
        dominated = true;
        break;
      }
    }
    // one of equal points: the first
    bool duplicate = false;
    for (std::size_t f : front)
      duplicate = duplicate || std::equal(values[f].begin(),
                                          values[f].begin() + static_cast<std::ptrdiff_t>(nobj),
                                          values[i].begin());
    if (!dominated && !duplicate) front.push_back(i);
  }
  std::stable_sort(front.begin(), front.end(),
                   [&](std::size_t a, std::size_t b) { return values[a][0] < values[b][0]; });
  return front;
}

Nsga2Outcome nsga2_search(
    const std::vector<double>& lower, const std::vector<double>& upper, std::size_t nobj,
    std::size_t width,
    const std::function<std::vector<double>(const std::vector<double>&)>& evaluate,
    const Nsga2Settings& s) {
  if (s.population < 8 || s.population % 4 != 0)
    throw InputError(
        fmt::format("population (--population) = {}: must be a multiple of 4, >= 8 "
                    "(NSGA-II pairs its parents by binary tournaments of four)",
                    s.population));
  if (s.generations < 0)
    throw InputError(fmt::format("generations (--generations) = {}: must be >= 0", s.generations));
  if (nobj < 2 || width < nobj + 1 || lower.empty() || lower.size() != upper.size())
    throw std::logic_error("nsga2_search: needs two objectives, a violation and bounds");
  const std::size_t dim = lower.size();
  BatchContext ctx{dim, nobj, width, &evaluate, std::max(1, s.threads), s.comm, 0};
  const bool root = !s.comm || s.comm->rank() == 0;
  Nsga2Outcome out;
  Snapshot snap;
  if (s.resume) {
    snap = read_checkpoint(s, dim, width);
    out.resumed_from = snap.generation;
  } else {
    snap.x = first_population(lower, upper, s.population, s.seed);
    snap.values = ctx.run(snap.x);
    snap.evaluations = ctx.evaluations;
  }
  const long evaluations0 = snap.evaluations - ctx.evaluations;
  auto save = [&] {
    if (root && !s.checkpoint_path.empty())
      write_file_atomic(s.checkpoint_path, checkpoint_text(s, dim, width, snap));
  };
  save();
  pagmo::problem prob{DesignUdp{lower, upper, nobj}};
  for (int g = snap.generation; g < s.generations; ++g) {
    pagmo::population pop{prob, 0u, generation_seed(s.seed, g + 1)};
    for (std::size_t i = 0; i < snap.x.size(); ++i)
      pop.push_back(snap.x[i], ctx.fitness(snap.values[i]));
    Archive archive;
    archive.add(snap.x, snap.values);
    pagmo::nsga2 alg(1u, 0.95, 10.0, 1.0 / static_cast<double>(dim), 50.0,
                     generation_seed(s.seed, g + 1));
    alg.set_bfe(pagmo::bfe{DesignBfe{&ctx, &archive}});
    pop = alg.evolve(pop);
    snap.x = pop.get_x();
    snap.values.clear();
    for (const auto& x : snap.x) snap.values.push_back(archive.find(x));
    snap.generation = g + 1;
    snap.evaluations = evaluations0 + ctx.evaluations;
    save();
    if (root && s.progress) s.progress(g + 1, s.generations);
  }
  out.x = std::move(snap.x);
  out.values = std::move(snap.values);
  out.generations = snap.generation;
  out.evaluations = ctx.evaluations;
  return out;
}

}  // namespace gmasim
