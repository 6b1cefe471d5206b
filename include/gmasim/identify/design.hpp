// gmasim design: multi-objective design of an actuator (issue 39, item 3). Declared design
// variables (any model key, or the drive's current) with bounds, two or more objectives and any
// constraints, searched by pagmo2's NSGA-II; the Pareto front of the last generation. Each
// candidate is the model with its variables set and compiled again, so everything its geometry
// derives (masses, coil resistance, reluctances, stiffness) follows (docs/experiments.md,
// "Design").
//
// The search is the same on 1 thread or many and on 1 MPI rank or N: one population evolves on
// every rank with the same seeds, and only its evaluations are shared out (candidate i on rank
// i mod N, each rank's on its threads), then summed over the ranks. A checkpoint after every
// generation holds the population exactly (17 significant digits), so a resumed search is the
// uninterrupted one bit for bit.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "gmasim/experiments/design_sweep.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/model/model.hpp"

namespace gmasim {

// The drive's own variables: `drive.current_pp_A` and `drive.current_min_A` (A) may be
// design variables beside the model's keys.
inline constexpr const char* kDesignDriveKeys[] = {"drive.current_pp_A", "drive.current_min_A"};

struct DesignVariable {
  std::string key;  // a model key as `gmasim model show` lists it, or a kDesignDriveKeys entry
  double lower = 0, upper = 0;  // in the key's own unit; lower < upper
};

// A quantity of a candidate (design_quantity_list() names them with their units):
//   stroke_um@T, hysteresis_um@T, B_pp_T@T   the drive's metrics at T degC (last period)
//   retention_pct@T1:T2                      100 stroke(T2) / stroke(T1)
//   coil_copper_loss_W@T                     the drive's I_rms^2 R(T) (coil_copper_loss_W)
//   temperature_rise_K@T                     that loss over housing_to_ambient_W_per_K
//   bandwidth_Hz, first_resonance_Hz         small-signal, at the reference temperature and
//                                            the bias (linear_frf_markers)
//   rods_mass_kg, rods_volume_m3             the rods' mass (derived from their geometry) and
//                                            volume
//   coil_resistance_ohm                      at T_ref (derived from the winding when given)
//   current_peak_A                           max |current| of the drive
struct DesignQuantity {
  std::string name;  // "stroke_um", ...
  double T1_C = std::numeric_limits<double>::quiet_NaN();
  double T2_C = std::numeric_limits<double>::quiet_NaN();
  std::string label() const;  // "stroke_um@20", "retention_pct@20:150", "rods_mass_kg"
};
// Parses "stroke_um@20", "retention_pct@20:150", "rods_mass_kg"; InputError naming `what` (the
// flag) and the form otherwise.
DesignQuantity parse_design_quantity(const std::string& text, const std::string& what);
std::string design_quantity_list();  // the names, their units and forms, for messages and help

struct DesignObjective {
  DesignQuantity quantity;
  bool maximise = false;
};

struct DesignConstraint {
  DesignQuantity quantity;
  bool at_most = true;  // quantity <= bound (false: >=)
  double bound = 0;
};
// "rods_mass_kg<=0.1", "temperature_rise_K@70>=0"; InputError naming --constraint otherwise.
DesignConstraint parse_design_constraint(const std::string& text);

struct DesignRequest {
  std::vector<DesignVariable> variables;
  std::vector<DesignObjective> objectives;  // two or more
  std::vector<DesignConstraint> constraints;
  // The drive every candidate is run with: a biased sine (Fig. 11), metrics over its last period.
  double current_min_A = -3.0, current_pp_A = 8.0, frequency_Hz = 10.0;
  double periods = 3.0;
  double dt_s = 0.0;  // 0: the automatic rule (auto_dt)
  // The small-signal markers' temperature and bias.
  double reference_temperature_C = 20.0, bias_A = 1.0;
  // NSGA-II (pagmo2): population a multiple of 4, at least 8; crossover and mutation as
  // pagmo's defaults (SBX p 0.95 eta 10, polynomial mutation p 1/n eta 50).
  int population = 24;
  int generations = 20;
  unsigned seed = 1;
  int threads = 0;               // per rank; 0: all hardware threads
  std::string checkpoint_path;   // written after every generation ("" : none)
  bool resume = false;           // continue from checkpoint_path
  Communicator* comm = nullptr;  // null: one process
  // Called on rank 0 after each generation: (generations done, generations in all).
  std::function<void(int, int)> progress;
};

// One candidate: its variables, every quantity the objectives and constraints name (in
// DesignResult::quantities' order), and whether it met the constraints.
struct DesignCandidate {
  std::vector<double> x;
  std::vector<double> values;
  double violation = 0;  // sum of the constraints' relative excesses (0: feasible)
  bool failed = false;   // did not compile or diverged (then values are NaN)
  bool feasible() const { return !failed && violation == 0.0; }
};

struct DesignResult {
  std::vector<DesignQuantity> quantities;   // the objectives' first, then the constraints'
  std::vector<DesignCandidate> population;  // the last generation
  std::vector<std::size_t> front;           // its feasible non-dominated members, by objective 1
  int generations = 0;                      // done, the resumed ones included
  int resumed_from = 0;                     // the checkpoint's generation (0: a fresh start)
  long evaluations = 0;                     // by this search (not counting a checkpoint's)
  double wall_time_s = 0;
  int ranks = 1, threads = 1;
};

// Checks the request against the base spec (every key known and settable, bounds finite and
// ordered, two objectives or more, population and generations), then searches. InputError names
// the flag and the value. A candidate that does not compile or whose run diverges is infeasible
// (failed), not an error.
DesignResult run_design(const ModelSpec& base, const DesignRequest& r);

// The evaluation of one candidate, as run_design does it: its model compiled, its drive run at
// each temperature its quantities name. The tests compare it with direct simulate() calls.
DesignCandidate evaluate_design(const ModelSpec& base, const DesignRequest& r,
                                const std::vector<DesignQuantity>& quantities,
                                const std::vector<double>& x);

// design.csv (the front), design_population.csv (the last generation) and design.json.
Report design_report(const DesignRequest& r, const DesignResult& res);

// ---------------------------------------------------------------------------------------
// The search itself, over any evaluator (the tests run it on problems with a known front).
// ---------------------------------------------------------------------------------------
struct Nsga2Settings {
  int population = 24, generations = 20;
  unsigned seed = 1;
  int threads = 1;
  std::string checkpoint_path, fingerprint;  // fingerprint: the problem, checked on resume
  bool resume = false;
  Communicator* comm = nullptr;
  std::function<void(int, int)> progress;
};
// evaluate(x) returns `width` numbers: the objectives to minimise (the first nobj), then the
// constraint violation (>= 0; 0 feasible), then anything the caller keeps. Candidates are shared
// over ranks and threads; evaluate must not depend on which.
struct Nsga2Outcome {
  std::vector<std::vector<double>> x, values;  // the last generation
  int generations = 0, resumed_from = 0;
  long evaluations = 0;
};
Nsga2Outcome nsga2_search(
    const std::vector<double>& lower, const std::vector<double>& upper, std::size_t nobj,
    std::size_t width,
    const std::function<std::vector<double>(const std::vector<double>&)>& evaluate,
    const Nsga2Settings& s);
// The indices of the feasible non-dominated points (values as nsga2_search returns them).
std::vector<std::size_t> feasible_front(const std::vector<std::vector<double>>& values,
                                        std::size_t nobj);

}  // namespace gmasim

namespace gmasim {
// gmasim sweep --grid on MPI ranks (issue 39, item 3): design d runs on rank d mod N (its points
// on that rank's threads), and rank 0 gathers every design's numbers exactly (17 significant
// digits), so its result is the one process's. The other ranks return their own designs only.
DesignSweepResult run_design_sweep_ranks(const ModelSpec& base, const std::vector<GridAxis>& axes,
                                         const SweepRequest& r, Communicator& comm,
                                         const ProgressFn& progress = {});
}  // namespace gmasim
