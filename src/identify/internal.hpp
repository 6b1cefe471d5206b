// Internal pieces of identify(): batch evaluation over threads and ranks, the GA driver,
// the checkpoint file, the Levenberg-Marquardt refinement and the covariance.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "gmasim/identify/identify.hpp"
#include "identify/communicator.hpp"

namespace gmasim::identify_detail {

// Wall-clock seconds since t (the report's timings).
inline double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Evaluates residual vectors at a batch of points: point i on rank i % R, and on each rank
// over `threads` worker threads. Every rank gets every result, bit-identical.
// An evaluation is a pure function of the point, so a point equal (bit for bit) to another of
// the batch or to one of the last kMemo points evaluated is not simulated again: its result is
// copied (a Jacobian's one-sided columns at a bound repeat the centre; the covariance's
// Jacobian at the optimum repeats the refinement's last). The memo is the same on every rank.
class BatchEvaluator {
 public:
  BatchEvaluator(const Objective& obj, int threads, Collective& comm)
      : obj_(obj), threads_(threads < 1 ? 1 : threads), comm_(comm) {}
  // ok[i] = residuals(points[i]) succeeded; res[i] has residual_count() values.
  std::vector<char> run(const std::vector<std::vector<double>>& points,
                        std::vector<std::vector<double>>& res);
  // Model evaluations run (all ranks); a result copied from the memo or the batch is not one.
  long evaluations() const { return evaluations_; }
  long reused() const { return reused_; }

 private:
  struct Memo {
    std::vector<double> u, r;
    char ok = 0;
  };
  static constexpr std::size_t kMemo = 64;
  // The distinct points not in the memo, evaluated over ranks and threads.
  std::vector<char> evaluate(const std::vector<std::vector<double>>& points,
                             std::vector<std::vector<double>>& res);
  const Memo* recall(const std::vector<double>& u) const;

  const Objective& obj_;
  int threads_;
  Collective& comm_;
  long evaluations_ = 0, reused_ = 0;
  std::vector<Memo> memo_;  // a ring of the last kMemo evaluations
  std::size_t memo_next_ = 0;
};

// Reduces (f, u) to the best over ranks (lowest f, then lowest rank); every rank gets it.
void global_best(Collective& comm, double& f, std::vector<double>& u);
bool any_rank(Collective& comm, bool flag);
long sum_ranks(Collective& comm, long v);

// ---- checkpoint -------------------------------------------------------------------------
struct IslandPopulation {
  unsigned seed = 0;
  std::vector<std::vector<double>> x;
  std::vector<double> f;
};

// Hashes of what a checkpoint's search depends on: the fitted parameters and bounds, the
// data, the objective settings and targets, and the layout (algorithm, ranks, islands, ...).
struct Fingerprints {
  std::string parameters, data, settings, layout;
};

struct Checkpoint {
  int version = 1;
  Fingerprints fp;  // of the run that wrote it
  std::string algorithm;
  int ranks = 1, islands = 0, population = 0, dim = 0;
  unsigned seed = 0;
  int generation = 0;
  long evaluations = 0;
  double wall_s = 0.0;
  double best_f = 0.0;
  std::vector<double> best_u;
  std::vector<HistoryEntry> history;
  std::vector<std::vector<IslandPopulation>> rank_islands;  // [rank][island]
};

Fingerprints fingerprints(const Objective& obj, const IdentifyOptions& o, int ranks);

// Text of one rank's islands (gathered to rank 0), and the whole file.
std::string islands_text(const std::vector<IslandPopulation>& islands);
std::string checkpoint_text(const Checkpoint& header, const std::vector<std::string>& rank_blocks);
// Throws InputError "file:line: ..." for a damaged file.
Checkpoint read_checkpoint(const std::string& path);
// Throws InputError naming what differs.
void check_compatible(const Checkpoint& c, const Fingerprints& fp, const std::string& path);

// ---- GA ---------------------------------------------------------------------------------
struct GaOutcome {
  std::vector<double> best_u;
  double best_f = 0.0;
  int generation = 0;
  long evaluations = 0;  // all ranks, GA only (including the resumed part)
  double wall_s = 0.0;   // this run's GA wall time
  long run_evaluations = 0;
  bool interrupted = false;
  bool resumed = false;
  std::vector<HistoryEntry> history;
};

GaOutcome run_ga(const Objective& obj, const IdentifyOptions& o, Collective& comm,
                 const std::vector<double>& start_u, double start_f);

// ---- refinement and covariance ------------------------------------------------------------
struct RefineOutcome {
  std::vector<double> u;
  double f = 0.0;
  int iterations = 0;
  bool interrupted = false;
  bool capped = false;  // stopped by eval_cap before converging
  std::string summary;
};

// Levenberg-Marquardt from u0 within [0, 1]^n; `fixed` >= 0 holds that component constant
// (profile likelihood); max_iterations < 0: o.refine_iterations; eval_cap >= 0: stops after
// the iteration that takes ev.evaluations() beyond it (RefineOutcome::capped).
RefineOutcome refine_lm(const Objective& obj, BatchEvaluator& ev, const std::vector<double>& u0,
                        const IdentifyOptions& o, Collective& comm,
                        const std::function<void(int, double)>& on_iteration, int fixed = -1,
                        int max_iterations = -1, long eval_cap = -1);

// Central-difference Jacobian at u (m x n, row-major) and the residuals at u; column `fixed`
// (if >= 0) is left zero.
bool jacobian(const Objective& obj, BatchEvaluator& ev, const std::vector<double>& u, double h,
              std::vector<double>& r, std::vector<double>& J, int fixed = -1);

// Parameter j of the fit at `value`: name, unit, scale and bounds; the interval fields keep
// their defaults.
FittedParameter fitted_parameter(const Objective& obj, std::size_t j, double value);

// What the profile stage spent and found.
struct ProfileOutcome {
  long budget = -1;         // evaluations it may spend (-1: no limit)
  long evaluations = 0;     // evaluations it spent
  double wall_s = 0.0;      // and its wall time
  bool budget_hit = false;  // a profile was cut short by the budget
  double lowest_f = 0.0;    // the lowest RMS [%] of any point it evaluated, and where
  std::vector<double> lowest_u;
};

// Linearised intervals and correlations from the Jacobian at the optimum u (RMS f); then
// profile-likelihood intervals for the parameters at a bound or whose linearised interval
// leaves the bounds, within prof.budget evaluations (prof: what they spent and found).
void fill_covariance(const Objective& obj, BatchEvaluator& ev, const std::vector<double>& u,
                     double f, const IdentifyOptions& o, Collective& comm, IdentifyResult& out,
                     ProfileOutcome& prof);

}  // namespace gmasim::identify_detail
