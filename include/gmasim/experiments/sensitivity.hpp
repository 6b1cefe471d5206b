// `gmasim sensitivity`: the derivative of every claim of the paper (data/claims.toml) and of
// a few simulate metrics with respect to the model's parameters, by central differences at
// two step sizes, and what they say about identifiability (correlations, near-null
// directions). docs/experiments.md, "Sensitivity".
//
//   S_ij = d q_i / d ln p_j        log step: p_j > 0 by its row's rule
//   (gmasim/model/parameters.hpp) S_ij = d q_i / d p_j           absolute step: a parameter that
//   may be zero or negative
//
// The quantities are a list of named scalars: the claims (their `ours`, exactly as `gmasim
// reproduce` scores them), the metric quantities (a simulate run's Metrics field at one
// operating point: builtin_metric_quantities(), one row each), and, from C++, functions of the
// compiled model.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "gmasim/experiments/claims.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/reproduce.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

// ---------------------------------------------------------------------------------------
// Claims from only the experiments they need
// ---------------------------------------------------------------------------------------
// The claims `ids` of o.claims (nullptr: the built-in data; ids empty: every claim), scored
// as run_reproduce(m, o).claims scores them, from only the points of the study they are
// taken at: the sweep points at their conditions (with their reference runs), the FRF's
// small-signal curves at their temperatures (no stepped sine: no claim reads it), the
// tracking, ablation and 20-150 degC runs they need, the thermal expansion. Every point is
// the same run as in the full study, so the numbers are the same (tested; a tracking claim's
// note names the smallest error among the temperatures run). A claim whose
// kind this planner does not know (a new extractor) makes it run the whole study.
// Throws InputError for an unknown id.
std::vector<Claim> run_claims(const Model& m, const ReproduceOptions& o,
                              const std::vector<std::string>& ids = {});

// ---------------------------------------------------------------------------------------
// Quantities
// ---------------------------------------------------------------------------------------
// A metric of one simulate run: a biased sine of current_pp_A peak to peak from -3 A at
// frequency_Hz and temperature_C, 3 periods, measured over the last (the sweep's settings,
// SweepRequest's defaults).
struct MetricQuantity {
  std::string name;                   // e.g. "stroke_um@20C_8A_10Hz"
  std::string unit;                   // of the value
  double (*read)(const Result& run);  // the value, from a simulate run with the energy ledger
  double temperature_C, current_pp_A, frequency_Hz;
  double relative_scale;    // its scale (identifiability, flag floor): this x |value at p0|
  std::string description;  // what it is
};

// The built-in metric quantities: the table in src/experiments/sensitivity_quantities.cpp
// (one row each: the loop metrics and the energy ledger's losses).
std::vector<MetricQuantity> builtin_metric_quantities();

// A quantity computed from the compiled model by the caller (C++ only: tests, scripts).
// Must be deterministic and thread-safe (it is called from worker threads).
struct FunctionQuantity {
  std::string name, unit;
  std::function<double(const Model&)> evaluate;
  double scale = 1.0;  // its scale, in its unit (identifiability, flag floor)
};

// ---------------------------------------------------------------------------------------
// The request
// ---------------------------------------------------------------------------------------
enum class StepKind {
  Log,      // p (1 +- h): the parameter's rule says > 0; reported d q / d ln p
  Absolute  // p +- h s: it may be zero or negative; reported d q / d p
};

struct SensitivityParameter {
  std::string name;    // dotted name, unit suffix optional ("rod1.k_j", "material.x")
  double scale = 0.0;  // Absolute steps: s [the parameter's unit]; 0: |p| (an error if p = 0)
};

// The numeric settings of a run: the rows of its request table
// (gmasim/experiments/experiment_fields.hpp), from which the CLI options, the Python keyword
// arguments and sensitivity.json's settings are generated. The defaults are typed here only.
struct SensitivitySettings {
  // The two relative steps h (docs/experiments.md, "Sensitivity": the rule and why these).
  double step_large = 1e-2, step_small = 2.5e-3;
  // An entry is flagged when its two estimates differ by more than `agreement` x the larger
  // magnitude, unless both are below floor_fraction x the quantity's scale.
  double agreement = 0.10, floor_fraction = 1e-3;
  // Identifiability: singular values below near_null_ratio x the largest are near-null.
  double near_null_ratio = 1e-3;
  // ReproduceOptions::quick: the claims scored on the quick study's grids. Only the claims'
  // own points run either way, and the quick grids hold every built-in claim's point, so for
  // the built-in claims this changes neither the numbers nor the cost.
  bool quick = false;
  // Claims: of `claims` (nullptr: the built-in data/claims.toml); the not-applicable ones are
  // never quantities. With use_claims false, none.
  bool use_claims = true;
  int threads = 0;  // 0: all hardware threads
};

struct SensitivityRequest : SensitivitySettings {
  std::vector<SensitivityParameter> parameters;
  const ClaimsData* claims = nullptr;  // see use_claims
  std::vector<MetricQuantity> metrics = builtin_metric_quantities();
  std::vector<FunctionQuantity> functions;
  // Keep only the quantities with these names (claim ids, metric or function names); empty:
  // all. An unknown name is an InputError.
  std::vector<std::string> only;
  // The units' grids (sweeps, 20-150 degC runs, ablation) advance in SIMD lanes where the model
  // allows (gmasim/simulate/lanes.hpp); false: one simulate() per run. The metric runs book the
  // energy ledgers, which the lanes do not carry: they run simulate() either way.
  bool lanes = true;
};

// "All numeric parameters of the model that a user would vary": every number of the spec,
// in file order, except the reference temperature (a convention: where Table 4 holds), the
// thermal network (only self-heating runs read it; no quantity does) and the numbers that
// are 0 (a switched-off feature; an absolute step would need a scale).
std::vector<SensitivityParameter> model_parameters(const ModelSpec& spec);

// ---------------------------------------------------------------------------------------
// The result
// ---------------------------------------------------------------------------------------
struct ParameterInfo {
  std::string name;  // the full dotted key
  std::string unit;
  double value = 0;
  StepKind step = StepKind::Log;
  double scale = 0;  // the step's scale: |p| (Log) or s (Absolute) [unit]
  std::string rule;  // the row's rule ("> 0", "any", ...)
};

enum class QuantityKind { Claim, Metric, Function };

struct QuantityInfo {
  std::string name, unit;
  QuantityKind kind = QuantityKind::Claim;
  double value = 0;          // at the model's parameters (NaN: not computable there)
  double scale = 0;          // the tolerance scale (NaN: none; the quantity is left out of
                             // identifiability)
  std::string scale_source;  // how the scale was chosen ("tolerance 3 pp", ...)
  std::string note;          // the claim's note at p0 (why it is NaN, ...)
};

// Entry flags. Ok: the two estimates agree.
enum class EntryFlag {
  Ok,
  Disagree,    // |S_large - S_small| > agreement x max(|S_large|, |S_small|)
  NonFinite,   // a value at a stencil point is NaN/Inf (diverged, not computable)
  StepRefused  // a stencil point breaks a rule of the model (ModelSpec::set, compile)
};
const char* entry_flag_name(EntryFlag f);  // "ok", "disagree", "nonfinite", "step_refused"

struct SensitivityEntry {
  // Log: d q / d ln p; Absolute: d q / d p [q unit / p unit], at each step size.
  double derivative_large = 0, derivative_small = 0;
  // derivative x (1 for Log, s for Absolute): the change of q per unit relative change of
  // the parameter's scale [q unit], the number the heatmap and identifiability use
  double scaled_large = 0, scaled_small = 0;
  double disagreement = 0;  // |scaled_large - scaled_small| / max(|.|, floor)
  EntryFlag flag = EntryFlag::Ok;
  std::string message;  // why it is flagged (the refused step's message, ...)
};

struct Direction {            // a right singular vector of the scaled Jacobian
  double singular_value = 0;  // change of the quantities [tolerances] per unit step along it
  double ratio = 0;           // singular_value / the largest
  bool near_null = false;     // ratio < near_null_ratio
  // singular_value < 1: a change of the parameters by a factor e along it moves the
  // quantities (root-sum-square) by less than one tolerance; the claims do not pin it down
  bool weak = false;
  std::vector<double> components;  // per parameter, unit norm, the largest positive
};

struct Identifiability {
  std::vector<std::string> quantities;  // those with a scale and finite entries (rows)
  std::vector<std::string> excluded;    // "<name>: why"
  // J_s[i][j] = scaled_large_ij / scale_i: tolerances per unit relative parameter change
  std::vector<std::vector<double>> jacobian;
  std::vector<double> column_norm;    // |J_s[:, j]|: how strongly the claims see parameter j
  std::vector<Direction> directions;  // all, by decreasing singular value
  // From C = (D^T J_s^T J_s D)^-1 (D the column normalisation; singular values below 1e-6 of
  // the largest raised to it, so a direction no quantity sees keeps a large variance).
  std::vector<std::vector<double>> correlation;  // NaN for a parameter no quantity sees
  std::vector<double> std_dev;  // sqrt(C_jj): in units of the scale per tolerance (NaN: unseen)
  double condition = 0;         // largest / smallest singular value of J_s D (inf: singular)
  int rank = 0;                 // singular values above near_null_ratio x the largest
};

struct SensitivityResult {
  std::vector<ParameterInfo> parameters;
  std::vector<QuantityInfo> quantities;
  // entries[i][j]: quantity i, parameter j
  std::vector<std::vector<SensitivityEntry>> entries;
  Identifiability identifiability;
  SensitivitySettings settings;  // the request's (threads: as asked; the count used below)
  long evaluations = 0;          // models evaluated: 1 + 4 per parameter
  long runs = 0;  // work items run: experiment parts (a sweep, the FRF, ...) x models
  int threads = 0;
  double wall_time_s = 0;
  int flagged() const;  // entries not Ok
};

// Evaluates every quantity at the model and at p_j (1 +- h) or p_j +- h s for each parameter
// and both steps (4 evaluations per parameter), in parallel (experiment points of all the
// evaluations share one work list; the result does not depend on the thread count).
// Throws InputError for an unknown parameter or quantity, an Absolute parameter at 0 without
// a scale, steps outside (0, 0.5) or not distinct, a quantity that is not finite at p0 is
// kept (NaN row, flagged), a stencil point the model refuses is flagged (StepRefused).
SensitivityResult run_sensitivity(const Model& m, const SensitivityRequest& r,
                                  const ProgressFn& progress = {});

// The identifiability of a Jacobian (rows quantities with their scales, columns parameters);
// run_sensitivity calls it on its own entries. Exposed for tests and other Jacobians.
Identifiability analyse_identifiability(const std::vector<std::string>& quantities,
                                        const std::vector<double>& scales,
                                        const std::vector<std::vector<double>>& scaled_jacobian,
                                        std::size_t parameters, double near_null_ratio);

// A direction as text: "+0.71 ln(rod1.k_j) -0.70 ln(rod2.k_j)" (components >= 0.1 in
// magnitude; an Absolute parameter reads "p/s").
std::string direction_text(const Direction& d, const std::vector<ParameterInfo>& params);

// ---- reports (io: src/io/sensitivity_output.cpp) ----------------------------------------
// Long-format CSV: one row per (quantity, parameter): quantity, quantity_unit, kind,
// quantity_value, quantity_scale, parameter, parameter_unit, parameter_value, step,
// derivative_unit, derivative_h_large, derivative_h_small, scaled_h_large, scaled_h_small,
// per_scale (scaled_h_large / quantity_scale), disagreement, flag, message.
std::string sensitivity_csv(const SensitivityResult& r);
// JSON: settings, parameters, quantities, entries keyed "/entries/<quantity>/<parameter>/...",
// the flagged entries, cost; `model` labels it.
std::string sensitivity_json(const SensitivityResult& r, const std::string& model);
// JSON: the identifiability (rows, columns, J_s, singular values, directions with their
// text, correlations, standard deviations).
std::string identifiability_json(const SensitivityResult& r, const std::string& model);

}  // namespace gmasim
