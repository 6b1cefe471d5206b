// `gmasim reproduce`: the whole study of the paper on one model, and the claims table
// (READING-NOTES' list of the paper's numbers, each beside ours with a stated tolerance).
// The claims themselves are data (data/claims.toml, gmasim/experiments/claims.hpp); score_claims
// computes ours for each with the extractor its kind names.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "gmasim/experiments/claims.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/model/model.hpp"

namespace gmasim {

struct Claim {
  std::string id;         // short stable key, e.g. "stroke_drop_8A"
  std::string claim;      // what the paper says, in words
  std::string source;     // "section 4.4.4, Fig. 13"
  double paper = 0.0;     // the paper's value (NaN when the claim is not a number)
  double ours = 0.0;      // our value (NaN when we cannot compute it)
  std::string unit;       // "%", "um", "Hz", ...
  std::string tolerance;  // the rule, in words ("|ours - paper| <= 3 pp")
  bool pass = false;
  bool applicable = true;    // false: needs measurements we do not have
  std::string note;          // why it passes/fails, or why it is not applicable
  std::string kind;          // the extractor (ClaimSpec::kind)
  ClaimCondition condition;  // where it holds (NaN fields: not part of the claim)
  // The model was fitted to it (its [calibration] fitted_claims: a target of the calibration,
  // or set by a chosen constant); otherwise it is a prediction.
  bool fitted = false;
  double rel_diff() const;  // (ours - paper)/|paper|, NaN if not applicable
};

struct ReproduceOptions {
  int threads = 0;
  bool quick = false;  // smaller grids (tests)
  // The grids' runs (sweeps, ablation, 20-150 degC runs, loops) advance in SIMD lanes where the
  // model allows (gmasim/simulate/lanes.hpp); false: one simulate() per run.
  bool lanes = true;
  // The claims to score; nullptr: the built-in data/claims.toml. Not owned.
  const ClaimsData* claims = nullptr;
};

struct ReproduceResult {
  // The requests, kept for the reports.
  SweepRequest sweep_10Hz_request, sweep_dynamic_request;
  FrfRequest frf_request;
  // The large-signal stepped sine (+-1 A about the bias, 20 and 70 degC) of the resonance
  // amplitude claim (section 3.4); the small-signal frf above carries the other FRF claims.
  FrfRequest frf_large_request;
  TrackRequest track_request;
  AblateRequest ablate_request;
  ParamsVsTemperatureRequest params_request;

  SweepResult sweep_10Hz;     // the paper's grid, 20-70 degC x 6/8/10/12 A x 10 Hz
  SweepResult sweep_dynamic;  // 20-70 degC x 6/8 A x 100/200/400 Hz (Fig. 17 conditions)
  FrfResult frf;
  FrfResult frf_large;
  TrackResult track;
  AblateResult ablate;
  ParamsVsTemperatureResult params;
  ThermalExpansionResult thermal;
  // Hysteresis loops y(I) over the last period, 8 A 10 Hz, one per temperature
  // (columns temperature_C, current_A, y_um, B_T).
  TimeSeries loops;
  std::vector<Claim> claims;
  double wall_time_s = 0.0;
  std::string model_source;
  std::string model_readings;  // the options in force, e.g. "eq10: mean_field, kelvin"
};

// The study's hysteresis loops (ReproduceResult::loops): y(I) and B(I) over the last of 2
// periods of an 8 A, 10 Hz biased sine at 20, 30, 40, 50, 60, 70, 100 and 150 degC, every 20th
// step; the runs in SIMD lanes where `lanes` and the model allow (ReproduceOptions::lanes).
TimeSeries hysteresis_loops(const Model& m, int threads = 0, bool lanes = true);

ReproduceResult run_reproduce(const Model& m, const ReproduceOptions& o,
                              const ProgressFn& progress = {});

// One Claim per ClaimSpec of `data`, in its order: ours from the study by the extractor of
// the claim's kind, pass/fail by its tolerance. A condition the study did not run gives
// ours = NaN (fail) with a note saying so.
std::vector<Claim> score_claims(const ReproduceResult& r, const ClaimsData& data);

// How many claims pass, of how many applicable; and apart, the fitted ones and the predictions.
struct ClaimCount {
  int pass = 0, applicable = 0;
  int fitted_pass = 0, fitted = 0, predicted_pass = 0, predicted = 0;
};
// "claims: F of Nf fitted pass; P of Np predicted pass"
std::string fitted_predicted_line(const ClaimCount& n);

// Marks the claims the model was fitted to (its spec's [calibration] fitted_claims). Throws
// InputError naming the model file and line for an id that is not a claim of `claims`.
void mark_fitted(std::vector<Claim>& claims, const ModelSpec& spec);
ClaimCount count_claims(const std::vector<Claim>& claims);

// The claims table as markdown (one row per claim) and the summary line "N of M pass".
std::string claims_markdown(const std::vector<Claim>& claims);

// Another model (e.g. one calibrated reading) scored on the same claims.
struct ComparedModel {
  std::string name, readings;
  std::vector<Claim> claims;
};
// One row per applicable claim, one column per compared model ("" if none).
std::string comparison_markdown(const std::vector<ComparedModel>& models);

// The claims as a report table (columns id, claim, source, kind, paper, ours, unit,
// rel_diff, tolerance, result, pass, fitted, the condition: temperature_C, reference_temperature_C,
// current_pp_A, frequency_Hz, amplitude_um (empty/null where not part of the claim), note).
Report claims_report(const std::vector<Claim>& claims);

// Writes DIR/report.md, DIR/claims.{csv,json}, and every experiment's data as CSV and JSON
// in DIR/data (atomically). Figures are rendered by the Python package (gmasim.report_figures,
// through run_python: python_exe, no shell; python_path where the package is) into
// DIR/figures/*.png|svg when python_exe is not empty; the report links them.
// Returns the markdown of the report.
std::string write_reproduce_outputs(const Model& m, const ReproduceResult& r,
                                    const std::string& dir, const std::string& python_exe,
                                    const std::string& python_path);

// The committed page (docs/reproduction.md): the claims table, the compared readings, and
// the figures of out_dir (copied next to the page). Written atomically.
// Explanations of failing claims, keyed by claim id: a markdown file whose "### <id>"
// headings each open one explanation (the text up to the next "### " heading or the end).
// Text before the first heading is ignored. Throws InputError naming file:line for a
// heading without an id or an id given twice.
std::vector<std::pair<std::string, std::string>> load_claim_notes(const std::string& path);

// The ids of the failing applicable claims that `notes` does not explain.
std::vector<std::string> unexplained_failures(
    const std::vector<Claim>& claims,
    const std::vector<std::pair<std::string, std::string>>& notes);

// docs/reproduction.md: the claims table, the compared readings, the figures and, for every
// failing claim, its explanation from `notes` (or "no explanation recorded").
void write_reproduction_doc(const ReproduceResult& r, const std::vector<ComparedModel>& compared,
                            const std::string& doc_path, const std::string& out_dir,
                            const std::vector<std::pair<std::string, std::string>>& notes = {});

}  // namespace gmasim
