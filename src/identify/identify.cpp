// identify(): GA (archipelago.cpp) -> Levenberg-Marquardt (refine.cpp) -> covariance
// (covariance.cpp) -> per-condition report at the optimum.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "gmasim/errors.hpp"
#include "gmasim/model/validate.hpp"
#include "internal.hpp"

namespace gmasim {

using namespace identify_detail;

namespace {

using Clock = std::chrono::steady_clock;

// The options no other part checks before the search needs them.
void check_options(const IdentifyOptions& o) {
  if (!is_island_algorithm(o.algorithm))
    throw InputError(
        fmt::format("--algorithm {}: must be {}", o.algorithm, island_algorithm_list()));
  auto positive = [](int v, const char* what) {
    if (v < 1) throw InputError(fmt::format("{} {}: must be >= 1", what, v));
  };
  positive(o.islands, "--islands");
  positive(o.migrate_every, "--migrate-every");
  positive(o.migrants, "--migrants");
  if (o.population < 8)
    throw InputError(fmt::format("--population {}: must be >= 8", o.population));
  // Counts that become memory and time (issue 19, item 4): each island holds a population,
  // each individual an evaluation per generation.
  if (o.islands > kMaxIslands)
    throw InputError(fmt::format(
        "--islands {}: at most {} per rank (each holds a population); use MPI ranks for more",
        o.islands, kMaxIslands));
  if (o.population > kMaxPopulation)
    throw InputError(fmt::format("--population {}: at most {} individuals per island", o.population,
                                 kMaxPopulation));
  if (static_cast<double>(o.islands) * o.population * std::max(1, o.generations) >
      kMaxGaEvaluations)
    throw InputError(fmt::format(
        "--islands {} x --population {} x --generations {} = {:.3g} evaluations per rank: more "
        "than {:g} (days of work); lower one of them",
        o.islands, o.population, o.generations,
        static_cast<double>(o.islands) * o.population * std::max(1, o.generations),
        kMaxGaEvaluations));
  if (o.generations > kMaxGenerations)
    throw InputError(fmt::format("--generations {}: at most {}", o.generations, kMaxGenerations));
  if (o.threads < 0 || o.threads > kMaxThreads)
    throw InputError(
        fmt::format("--threads {}: must be 0 (all cores) or in [1, {}]", o.threads, kMaxThreads));
  if (o.migrants >= o.population)
    throw InputError(
        fmt::format("--migrants {}: must be < the population {}", o.migrants, o.population));
  if (o.generations < 0)
    throw InputError(fmt::format("--generations {}: must be >= 0", o.generations));
  if (o.refine_iterations < 0)
    throw InputError(fmt::format("--refine-iterations {}: must be >= 0", o.refine_iterations));
  // Below ~1e-8 the central differences of a double objective are rounding: a Jacobian of zeros
  // that the report then blamed on the data ("not determined").
  if (!(o.fd_step >= 1e-8 && o.fd_step < 0.1))
    throw InputError(
        fmt::format("--fd-step {:g}: must be in [1e-8, 0.1) (a relative step; below "
                    "1e-8 the differences are rounding)",
                    o.fd_step));
  if (o.mpi_every < 0) throw InputError(fmt::format("--mpi-every {}: must be >= 0", o.mpi_every));
  if (o.checkpoint_every < 1)
    throw InputError(
        fmt::format("--checkpoint-every {}: must be >= 1 (generations between checkpoints)",
                    o.checkpoint_every));
  if (o.profile_evaluations < -1)
    throw InputError(fmt::format(
        "--profile-evaluations {}: must be >= 0 (0: no limit), or -1 (as many as the search)",
        o.profile_evaluations));
}

// The start model must evaluate: a search from a model that cannot be simulated under
// these settings would penalise every candidate alike and end "successfully" with nothing
// determined (issue 8). A candidate that fails later is penalised; the start is not.
void check_start_evaluates(const Objective& obj, const std::vector<double>& u_start, double f_start,
                           const std::string& source) {
  if (f_start < Objective::kPenalty) return;
  const std::string why = obj.failure_reason(u_start);
  // The start point is the model's values unless the fit spec gave a start or a value was moved
  // into its bounds: then the model file may evaluate fine, and the message says what moved.
  if (!obj.notes().empty())
    throw InputError(fmt::format(
        "the start point cannot be evaluated on the data and targets (--data, --fit): {}; it is "
        "the start model {} (--model) with the fit's changes:\n  {}\nchange the start values or "
        "the bounds in the fit spec (--fit) before searching",
        why.empty() ? "its error is not finite" : why, source, fmt::join(obj.notes(), "\n  ")));
  throw InputError(fmt::format(
      "the start model {} (--model) cannot be evaluated on the data and targets (--data, "
      "--fit): {}{}",
      source, why.empty() ? "its error is not finite" : why,
      "; fix the start model or the settings before searching"));
}

// Levenberg-Marquardt from the GA's best (u, f), which it replaces when it is better; its
// iterations continue the GA's history in res.
void refine_champion(const Objective& obj, BatchEvaluator& ev, const GaOutcome& ga,
                     const IdentifyOptions& o, Collective& comm, Clock::time_point t0,
                     std::vector<double>& u, double& f, IdentifyResult& res) {
  const double wall_before = ga.history.empty() ? 0.0 : ga.history.back().wall_s - ga.wall_s;
  const long ga_evals = ga.evaluations;
  if (o.refine && !res.interrupted && o.refine_iterations > 0) {
    auto on_iter = [&](int it, double rms) {
      HistoryEntry h;
      h.phase = "refine";
      h.step = it;
      h.evaluations = ga_evals + ev.evaluations();
      h.best_rms_pct = rms;
      h.wall_s = wall_before + std::chrono::duration<double>(Clock::now() - t0).count();
      res.history.push_back(h);
      if (comm.rank() == 0 && o.progress)
        o.progress({"refine", it, o.refine_iterations, "", rms, h.evaluations, 0.0, h.wall_s});
    };
    RefineOutcome ro = refine_lm(obj, ev, u, o, comm, on_iter);
    res.refine_summary = ro.summary;
    res.interrupted = ro.interrupted;
    if (ro.f < f) {  // never worse than the GA champion
      f = ro.f;
      u = ro.u;
      res.best_found_by = "refinement";
    }
  } else if (!o.refine || o.refine_iterations == 0) {
    res.refine_summary = "no refinement (--no-refine)";
  } else {
    res.refine_summary = "interrupted before the refinement";
  }
}

// The fitted parameters at the optimum (u, f) with their intervals; after an interruption
// the values without intervals (a clean, fast stop). prof.budget: the profile's allowance.
void set_parameters(const Objective& obj, BatchEvaluator& ev, const std::vector<double>& u,
                    double f, const IdentifyOptions& o, Collective& comm, IdentifyResult& res,
                    ProfileOutcome& prof) {
  prof.lowest_f = f;
  prof.lowest_u = u;
  if (!res.interrupted) {
    IdentifyOptions oc = o;
    if (!o.refine || o.refine_iterations == 0) {
      // Not refined: the point is not a minimum, a profile around it would mean nothing.
      oc.profile = false;
      res.notes.push_back(
          "not refined: the intervals are linearised at the GA champion, which "
          "is not a minimum; refine for meaningful intervals");
    }
    if (prof.budget == 0 && oc.profile) {  // the stage's budget is spent
      oc.profile = false;
      res.notes.push_back(
          "the profile's budget was spent before these intervals: they are linearised "
          "(raise --profile-evaluations for profiles)");
    }
    const long before = ev.evaluations();
    const auto t0 = Clock::now();
    fill_covariance(obj, ev, u, f, oc, comm, res, prof);
    auto& se = res.stage_evaluations;
    se.profile += prof.evaluations;
    se.covariance += ev.evaluations() - before - prof.evaluations;
    se.profile_s += prof.wall_s;
    se.covariance_s += seconds_since(t0) - prof.wall_s;
    return;
  }
  const auto p = obj.to_params(u);
  res.parameters.clear();
  for (std::size_t j = 0; j < obj.dim(); ++j) {
    FittedParameter fp = fitted_parameter(obj, j, p[j]);
    fp.std_error = std::nan("");
    fp.ci_low = fp.ci_high = fp.wald_low = fp.wald_high = std::nan("");
    fp.determined = false;
    fp.ci_method = "none";
    res.parameters.push_back(fp);
  }
  res.covariance_note = "interrupted: no confidence intervals";
}

// The intervals at (u, f); when a profile refit finds a lower error, that point is refined
// and becomes the optimum (its intervals recomputed with what is left of the profile's
// budget), up to kRounds times: the written point is the best any stage found.
void settle_optimum(const Objective& obj, BatchEvaluator& ev, const IdentifyOptions& o,
                    Collective& comm, std::vector<double>& u, double& f, IdentifyResult& res) {
  constexpr int kRounds = 3;
  auto& se = res.stage_evaluations;
  se.profile_budget = o.profile_evaluations < 0    ? se.search
                      : o.profile_evaluations == 0 ? -1
                                                   : o.profile_evaluations;
  for (int round = 0;; ++round) {
    ProfileOutcome prof;
    prof.budget = se.profile_budget < 0 ? -1 : std::max(0L, se.profile_budget - se.profile);
    set_parameters(obj, ev, u, f, o, comm, res, prof);
    if (res.interrupted || !(prof.lowest_f < f * (1.0 - 1e-9))) return;
    res.notes.push_back(fmt::format(
        "the profile likelihood found a lower error (RMS {:.6g} % < {:.6g} %): that point was "
        "refined and is the written optimum",
        prof.lowest_f, f));
    u = prof.lowest_u;
    f = prof.lowest_f;
    res.best_found_by = "profile";
    const long before = ev.evaluations();
    const auto t0 = Clock::now();
    const RefineOutcome ro = refine_lm(obj, ev, u, o, comm, {});
    se.refine += ev.evaluations() - before;
    se.refine_s += seconds_since(t0);
    res.interrupted = ro.interrupted;
    if (ro.f < f) {
      u = ro.u;
      f = ro.f;
    }
    if (round + 1 == kRounds) {  // the intervals at the final point, linearised only
      ProfileOutcome none;
      none.budget = 0;
      set_parameters(obj, ev, u, f, o, comm, res, none);
      return;
    }
  }
}

}  // namespace

std::string island_algorithm_list() { return choice_list(kIslandAlgorithms); }

bool is_island_algorithm(std::string_view name) {
  for (const std::string_view a : kIslandAlgorithms)
    if (a == name) return true;
  return false;
}

IdentifyResult identify(const ModelSpec& start, const MeasurementSet& data, const FitSpec& fit,
                        const IdentifyOptions& o) {
  const auto t0 = Clock::now();
  auto serial = make_serial_communicator();
  Collective& comm = collective(o.comm ? *o.comm : *serial);
  check_options(o);

  const Objective obj(start, data, fit, o.objective);
  const int threads = o.threads > 0
                          ? o.threads
                          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  BatchEvaluator ev(obj, threads, comm);

  IdentifyResult res;
  res.ranks = comm.size();
  res.islands = o.islands;
  res.population = o.population;
  res.algorithm = o.algorithm;
  res.notes = obj.notes();

  const std::vector<double> u_start = obj.start_unit();
  const double f_start = obj.rms_pct(u_start);
  res.start_rms_pct = f_start;
  check_start_evaluates(obj, u_start, f_start, start.source);

  // ---- global search, local refinement ------------------------------------------------
  const GaOutcome ga = run_ga(obj, o, comm, u_start, f_start);
  res.history = ga.history;
  res.generations_done = ga.generation;
  res.resumed = ga.resumed;
  res.interrupted = ga.interrupted;
  res.ga_rms_pct = ga.best_f;
  res.ga_evals_per_s = ga.wall_s > 0 ? static_cast<double>(ga.run_evaluations) / ga.wall_s : 0.0;
  std::vector<double> u = ga.best_u;
  double f = ga.best_f;
  res.stage_evaluations.search = ga.evaluations + 1;  // with the start model's evaluation
  res.stage_evaluations.search_s = seconds_since(t0);
  const auto t_refine = Clock::now();
  refine_champion(obj, ev, ga, o, comm, t0, u, f, res);
  res.stage_evaluations.refine = ev.evaluations();
  res.stage_evaluations.refine_s = seconds_since(t_refine);

  // ---- intervals (and the best point any stage found) --------------------------------------
  settle_optimum(obj, ev, o, comm, u, f, res);
  res.unit_optimum = u;
  res.rms_pct = f;
  res.spec = obj.spec_at(u);
  const auto p_start = obj.to_params(u_start);
  for (std::size_t j = 0; j < res.parameters.size(); ++j) {
    res.parameters[j].start = p_start[j];
    if (j < res.correlation.size()) res.correlation[j][j] = 1.0;
  }
  if (comm.rank() == 0) {
    res.conditions = obj.condition_fits(u);
    res.targets = obj.target_fits(u);
  }
  res.evaluations = ga.evaluations + ev.evaluations() + 1;
  res.stage_evaluations.reused = ev.reused();
  res.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return res;
}

}  // namespace gmasim
