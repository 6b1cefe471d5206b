// Internal: the parts of `gmasim reproduce`'s study that some claims need (run_claims,
// run_sensitivity). A plan is a list of units (one sweep per current and frequency, the FRF,
// the tracking, the ablation, the 20-150 degC runs, the metric runs, ...); a unit runs on one
// model and fills its own slot of a PartResults, so units of many models can share one work
// list. assemble_claims() then scores the claims from the slots as run_reproduce would.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/reproduce.hpp"
#include "gmasim/experiments/sensitivity.hpp"

namespace gmasim::detail {

// The requests of run_reproduce's study (src/experiments/reproduce.cpp sets the same; the
// test RunClaims.MatchesTheFullStudy holds the two together).
struct StudyRequests {
  SweepRequest sweep_10Hz, sweep_dynamic;
  FrfRequest frf;
  FrfRequest frf_large;  // +-1 A stepped sine about the bias (the resonance amplitude claim)
  TrackRequest track;
  AblateRequest ablate;
  ParamsVsTemperatureRequest params;
};
StudyRequests reproduce_requests(bool quick);

enum class UnitKind {
  Full,
  Track,
  Ablate,
  Params,
  Frf,
  FrfLarge,
  Sweep10Hz,
  SweepDynamic,
  Metric,
  Functions
};

struct Unit {
  UnitKind kind;
  std::size_t index = 0;  // Sweep*: the sub-request; Metric: the operating point
};

struct ClaimPlan {
  bool quick = false;
  ClaimsData claims;   // the claims to score (not-applicable ones included: scored n/a)
  StudyRequests grid;  // the full study's requests (the extractors check conditions on them)
  bool full = false;   // a kind the planner does not know: run the whole study
  bool lanes = true;   // the grids' runs in SIMD lanes (with_lanes)
  std::vector<SweepRequest> sweeps_10Hz, sweeps_dynamic;  // one per (current, frequency)
  bool frf = false, frf_large = false, track = false, ablate = false, params = false;
  FrfRequest frf_request, frf_large_request;
  TrackRequest track_request;
  AblateRequest ablate_request;
  ParamsVsTemperatureRequest params_request;
  // Metric quantities: the distinct operating points, and each quantity's point.
  std::vector<SweepRequest> metric_points;
  std::vector<std::size_t> metric_point_of;
  std::vector<MetricQuantity> metrics;
  std::vector<FunctionQuantity> functions;
  std::vector<Unit> units;  // the most expensive first
};

// The plan for `claims` (every one of them is scored), `metrics` and `functions`.
ClaimPlan plan_claims(const ClaimsData& claims, bool quick, std::vector<MetricQuantity> metrics,
                      std::vector<FunctionQuantity> functions);
// The plan with its grids' runs in SIMD lanes (where the model allows) or not: the sweeps',
// the ablation's and the 20-150 degC runs' `lanes`.
ClaimPlan with_lanes(ClaimPlan p, bool lanes);

struct PartResults {
  std::vector<SweepResult> sweeps_10Hz, sweeps_dynamic;
  FrfResult frf, frf_large;
  TrackResult track;
  AblateResult ablate;
  ParamsVsTemperatureResult params;
  std::vector<Claim> full_claims;
  std::vector<double> metric_values;    // per metric quantity
  std::vector<double> function_values;  // per function quantity
  std::vector<std::string> errors;      // per unit: "" or what stopped it
};
PartResults empty_results(const ClaimPlan& p);

// Runs unit u of the plan on model m into `out` (its own slots only). A DivergenceError or
// InputError of the unit is recorded in out.errors[u] (the quantities it feeds are NaN).
void run_unit(const ClaimPlan& p, std::size_t u, const Model& m, PartResults& out);

// The claims scored from the units' results, in the order of p.claims; a claim fed by a unit
// that failed carries its error in the note.
std::vector<Claim> assemble_claims(const ClaimPlan& p, const Model& m, const PartResults& r);

// The units each claim reads (for messages): the indices into p.units.
std::string unit_name(const Unit& u);

}  // namespace gmasim::detail
