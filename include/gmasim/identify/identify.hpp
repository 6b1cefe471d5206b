// Parameter identification (issue 4): measured data -> calibrated model file.
//
//   MeasurementSet (docs/data.md)  +  FitSpec (which parameters, bounds, scalar targets)
//     -> Objective: weighted RMS of simulated vs measured displacement, % of peak-to-peak
//     -> identify(): multi-island GA (pagmo2 archipelago, ring migration; optionally one
//        archipelago per MPI rank with a champion ring between ranks), then
//        Levenberg-Marquardt refinement of the champion (Ceres), then the 95 % confidence
//        intervals and correlations from the Jacobian at the optimum.
//
// See docs/identify.md for the algorithms and why, and docs/data.md for the file formats.
#pragma once

#include <array>
#include <atomic>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

// =======================================================================================
// Measurements (docs/data.md)
// =======================================================================================
// What a record's columns hold (docs/data.md, "Columns").
enum class DriveInput {
  Current,  // current_A: the coil current [A], which drives the model
  Field     // field_A_per_m: the applied field H_c (eq. 7) of one rod [A/m]; the model is
            // driven by the coil current that produces it (found at every step)
};
enum class ResponseOutput {
  Displacement,  // displacement_um: the actuator output y [um] (eq. 20)
  Strain         // strain_ppm: one rod's strain x_i / l_i [1e-6] (eq. 15's x_i)
};
// How the measured response is referenced (relative strain, integrated induction-coil flux).
enum class OffsetMode {
  Absolute,     // compared as measured
  FirstSample,  // measured and simulated both taken relative to their first sample
  Fitted        // an unknown constant offset, eliminated by least squares per record
};
std::string offset_mode_name(OffsetMode m);
// The magnetic state a record starts from (condition key initial_state, docs/data.md).
enum class InitialState {
  Demagnetised,       // at rest in the demagnetised equilibrium at the first drive value
  NegativeRemanence,  // after a slow bipolar cycle of the record's amplitude A: 0 -> +A -> -A
                      // -> the first drive value (at zero drive: the negative remanence)
  PositiveRemanence   // the mirror: 0 -> -A -> +A -> the first drive value
};
std::string initial_state_name(InitialState s);

inline constexpr double kMaxField_A_per_m = 1e7;  // |field_A_per_m| limit (saturation ~1e5)
inline constexpr long kMaxPrecycles = 100;

struct MeasurementCondition {
  double temperature_C = 0.0;
  // Where temperature_C was read (the CSV's header or its sidecar, and the line; "" and 0 when
  // built in memory): an error about the temperature is reported there.
  std::string temperature_file;
  long temperature_line = 0;
  // Periodic (biased-sine) excitation when frequency_Hz > 0: then current_pp_A is set.
  double frequency_Hz = 0.0;
  double current_pp_A = 0.0;
  double current_min_A = -3.0;  // Fig. 11; used only with current_source = "sine"
  // Samples with t_s < compare_from_s are simulated but not compared (the transient from
  // the demagnetised start). Default: t0 + one period if periodic (and neither pre-cycled
  // nor started from a given initial_state), else t0.
  double compare_from_s = 0.0;
  std::string current_source = "measured";  // "measured" (the CSV current) or "sine"
  std::string label;                        // default: the file name without extension
  // Quasi-static record (no t_s column): the samples are equilibria in measurement order,
  // t_s holds their index 0, 1, 2, ...; the model moves through them with
  // quasi_static_step in increments chosen from the record (ObjectiveSettings).
  bool quasi_static = false;
  std::string rod;     // rod of the field_A_per_m / strain_ppm columns; "": the first rod
  long precycles = 0;  // passes of the record's own drive before the compared pass
  InitialState initial_state = InitialState::Demagnetised;  // before the pre-cycles
  OffsetMode offset = OffsetMode::Absolute;                 // of displacement_um / strain_ppm
  OffsetMode flux_offset = OffsetMode::Absolute;            // of flux_T
  // The prestress the record was measured at [MPa]: the stress in the first rod of
  // stack.rods; the record is simulated with the preload that gives it (its force replaces
  // the model's preload). NaN: the model's own preload.
  double prestress_MPa = std::numeric_limits<double>::quiet_NaN();
};

struct Measurement {
  std::string path;  // the CSV file
  MeasurementCondition condition;
  double weight = 1.0;
  DriveInput drive_kind = DriveInput::Current;
  ResponseOutput response_kind = ResponseOutput::Displacement;
  std::vector<double> t_s;    // [s]; quasi-static records: the sample index
  std::vector<double> drive;  // current_A [A] or field_A_per_m [A/m] (drive_kind)
  // The drive column as the CSV header names it: current_A, field_A_per_m or field_kA_per_m
  // (whose values are read x 1000 into `drive`, in A/m); "" for a record built in memory.
  std::string drive_header;
  std::vector<double> response;  // displacement_um [um] or strain_ppm [1e-6] (response_kind)
  std::vector<double> flux_T;    // empty if the file has no flux_T column
  bool periodic() const { return condition.frequency_Hz > 0.0; }
  // Column names and units of drive and response, as in the CSV header.
  std::string_view drive_column() const;
  std::string_view response_column() const;
  std::string_view response_unit() const;  // "um" or "ppm"
};

struct MeasurementSet {
  std::string manifest;  // path of the manifest ("" if built in memory)
  std::vector<Measurement> items;
};

// One CSV "[t_s,]current_A|field_A_per_m,displacement_um|strain_ppm[,flux_T]" with its
// condition in "# key = value" header comments and/or the sidecar <name>.toml. Throws InputError
// "file:line: ..." for an empty file, a bad header, mismatched columns, non-numeric cells, NaN/Inf,
// duplicate or decreasing time, fewer than 4 rows, a missing or contradictory condition.
Measurement load_measurement_csv(const std::string& path);
// The manifest (TOML, [[measurement]] file + weight); every file is loaded and checked.
MeasurementSet load_manifest(const std::string& path);

// Writes the CSV (with the condition as header comments), exact to the last bit for t_s and
// current_A, and a manifest listing the files; used for synthetic data and examples.
std::string measurement_csv(const Measurement& m);
void write_measurement_set(const MeasurementSet& set, const std::string& dir);

// =======================================================================================
// What to fit
// =======================================================================================
enum class ParamScale { Linear, Log };

struct FitParameter {
  std::string name;  // dotted model name with its unit suffix ("rod1.ja.k0_A_per_m")
  double lower = 0.0, upper = 0.0;
  ParamScale scale = ParamScale::Linear;
  bool has_start = false;  // start value given in the spec (else: the model's value)
  double start = 0.0;
  long line = 0;
};

// Scalar targets computed from a biased-sine run (or, for resonance, the bias point).
enum class TargetKind {
  StrokeUm,             // stroke at (T, pp, f) [um]
  HysteresisUm,         // hysteresis width at (T, pp, f) [um]
  BppT,                 // induction-coil flux density peak-to-peak at (T, pp, f) [T]
  StrokeChangePct,      // 100 (stroke(T) / stroke(T_ref) - 1) [%]
  HysteresisChangePct,  // the same for the hysteresis width [%]
  BppChangePct,         // the same for B p-p [%]
  RetentionPct,         // 100 stroke(T) / stroke(T_ref) [%]
  ResonanceHz,          // lowest natural frequency of eq. (15) at (T, bias current) [Hz]
  FrfPeakHz,    // peak of the small-signal |Y/I| at (T, bias) (FrfCurve::first_resonance_Hz) [Hz]
  BandwidthHz,  // -3 dB point of the small-signal |Y/I| at (T, bias) [Hz]
  ModulusGPa    // mean over the rods of the Delta-E modulus E_G (eq. 13) at rest at (T, bias)
                // [GPa]: Table 6's k_i = E A / l say about 30 GPa (READING-NOTES)
};
std::string target_kind_name(TargetKind k);

struct FitTarget {
  TargetKind kind = TargetKind::StrokeUm;
  std::string label;
  double temperature_C = 20.0, reference_temperature_C = 20.0;
  double current_pp_A = 8.0, current_min_A = -3.0, frequency_Hz = 10.0, bias_A = 1.0;
  double value = 0.0;   // the target value, in the kind's unit
  double weight = 1.0;  // relative to a measurement file of weight 1
  double scale = 0.0;   // normaliser: error % = 100 (sim - value) / scale; 0: |value|
  long line = 0;
  std::string claim;  // the claim this target stands for ([[target]] claim = "<id>"), or ""
};

struct FitSpec {
  std::string source;
  std::vector<FitParameter> parameters;
  std::vector<FitTarget> targets;
  // [[by_construction]] claim = "<id>", reason = "...": claims no target fits but a chosen
  // constant sets (eq. 21's sleeve length sets the 0.662 um/degC); they count as fitted.
  std::vector<std::pair<std::string, std::string>> by_construction;
};

// The claims a fit with this spec is fitted to: its targets' claims, then the
// by-construction ones (no duplicates). gmasim identify writes them into the fitted model's
// [calibration] fitted_claims; gmasim reproduce counts every other claim as a prediction.
std::vector<std::string> fitted_claims(const FitSpec& spec);

// A TOML file ([[parameter]] and [[target]] tables), or inline
// "name:lower:upper[:log][,name:lower:upper...]". Throws InputError.
// A [[target]] with `claim = "<id>"` takes its kind, value and condition from that claim
// (gmasim/experiments/claims.hpp): of the spec's top-level `claims = "file"` (relative to the spec)
// if it names one, else of `claims` if given, else of the built-in data/claims.toml.
struct ClaimsData;
FitSpec load_fit_spec(const std::string& file_or_inline);
FitSpec parse_fit_spec(const std::string& toml_text, const std::string& source_name,
                       const ClaimsData* claims = nullptr);

// =======================================================================================
// Objective
// =======================================================================================
struct ObjectiveSettings {
  // The measured records' step: dt_s if > 0, else period / steps_per_period. The scalar
  // targets take the claims' step (claim_dt, gmasim/simulate/simulate.hpp) whatever these say,
  // so that the fit computes each claim as gmasim reproduce scores it (issue 37).
  double dt_s = 0.0;                // fixed time step of the records; 0: the rule below
  double steps_per_period = 500.0;  // periodic records: dt = period / this
  double flux_weight = 0.0;         // weight of the flux_T residuals (files that have them)
  // Run length of the scalar-target simulations [periods]: 3, the periods of gmasim
  // reproduce's sweeps and 20-150 degC runs (SweepRequest, ParamsVsTemperatureRequest).
  double target_periods = 3.0;
  // Quasi-static records: the drive (current or field) moves in at most this many equal
  // increments over its whole range min..max; each sample-to-sample change is split into
  // ceil(|change| / (range / this)) quasi_static_step calls. The loop converges at second
  // order in the increment: 500 is within 1e-6 of the p-p of a 48 um loop
  // (tests/test_identify_records.cpp).
  double quasi_static_increments = 500.0;
  // The records advance together in SIMD lanes (gmasim/simulate/lanes.hpp) where the model and
  // the records allow (timed, current-driven, from rest), and so do the scalar targets' sine
  // runs; false: one scalar run per record and per sine run.
  bool lanes = true;
};
// The rules of ObjectiveSettings (steps per period in [8, 1e6], dt >= 0, target periods in
// [1, 1e4], flux weight in [0, 1e6], quasi-static increments in [10, 1e6]): one check for
// identify and `identify synthesize` (issue 19, item 6). Throws InputError naming the flag.
void validate(const ObjectiveSettings& s);

// Per-condition outcome at one parameter vector.
struct ConditionFit {
  std::string label, path;
  std::string overlay_file;  // "overlay_<label>.csv", unique and file-name safe
  MeasurementCondition condition;
  double weight = 1.0;
  std::size_t samples = 0, compared = 0;
  // pp, rms and max_err are in the record's response unit (response_unit: "um" for
  // displacement_um, "ppm" for strain_ppm records); fit_report.json names them
  // pp_<unit>, rms_<unit>, max_err_<unit>.
  std::string response_unit = "um";
  // The record's drive over its samples: "I p-p [A]" of current_A, "H p-p [kA/m]" of
  // field_A_per_m (the report's drive column; condition.current_pp_A is 0 for a field record).
  std::string drive_label = "I p-p [A]";
  double drive_pp = 0.0;  // in drive_label's unit
  double pp = 0.0;        // peak-to-peak of the measured response (compared samples)
  double rms = 0.0;       // RMS of simulated - measured
  double rms_pct = 0.0;   // rms / pp [%] (the paper's normalisation)
  double max_err = 0.0;
  // The constant added to the simulated response by the record's offset rule (offset =
  // first_sample or fitted; 0 for absolute), in the response unit, and the same for flux_T
  // [T] (flux_offset).
  double offset = 0.0;
  double flux_offset_T = 0.0;
  double flux_rms_pct = -1.0;  // -1: no flux column (or flux not fitted)
  bool failed = false;         // the simulation diverged or a value was invalid
  std::string error;
  // The loop's width at kLoopWidthFractions of the measured response's span (compared
  // samples), measured and simulated at the same levels (loop_widths), in the drive's unit:
  // kA/m of a field record, A of a current record (width_unit); NaN where a branch of the loop
  // does not cross the level. A law whose loop closes too early shows here first.
  std::string width_unit = "A";
  std::array<double, 4> width_measured{}, width_simulated{};
  // Overlay: t_s, current_A, measured_um, simulated_um, compared (1/0)
  TimeSeries overlay;
};

// The levels of ConditionFit's loop widths, as fractions of the measured response's span.
inline constexpr std::array<double, 4> kLoopWidthFractions = {0.2, 0.4, 0.6, 0.8};

// The horizontal width of a hysteresis loop (drive x, response y, sample by sample) at the levels
// L = lo + f (hi - lo), f in kLoopWidthFractions: at each level, the drive where y crosses L
// (linear between samples), on the half of the drive that holds its largest magnitude (a
// butterfly's two halves mirror each other; a unipolar loop has one), split by the drive's
// direction there; the width is |mean crossing while the drive falls - mean crossing while it
// rises|. NaN where either branch does not cross L. Units: x's.
std::array<double, 4> loop_widths(std::span<const double> x, std::span<const double> y, double lo,
                                  double hi);

struct TargetFit {
  std::string label, kind;
  double value = 0.0, simulated = 0.0, error_pct = 0.0, weight = 1.0;
  bool failed = false;
};

// The least-squares objective over a normalised parameter vector u in [0, 1]^n
// (u_j = 0 at the lower bound, 1 at the upper; log parameters are linear in log|p|).
// Immutable and cheap to copy (shared state); every method is const and thread-safe:
// each evaluation builds its own Model and State.
class Objective {
 public:
  // Throws InputError: unknown parameter, bad bounds, bounds that break model rules, a
  // measurement temperature at/above T_c, no data and no targets.
  Objective(const ModelSpec& start, const MeasurementSet& data, const FitSpec& fit,
            const ObjectiveSettings& settings = {});

  std::size_t dim() const;
  std::size_t residual_count() const;
  const std::vector<std::string>& names() const;  // resolved dotted names
  const std::vector<std::string>& units() const;
  const FitSpec& fit() const;
  const MeasurementSet& data() const;
  const ObjectiveSettings& settings() const;
  const ModelSpec& start_spec() const;
  const std::vector<std::string>& notes() const;  // e.g. start values clamped into bounds

  std::vector<double> start_unit() const;  // the start values in u-space
  std::vector<double> to_params(const std::vector<double>& u) const;
  std::vector<double> to_unit(const std::vector<double>& p) const;
  // d theta_j / d u_j where theta = p (linear) or ln|p| (log).
  std::vector<double> theta_per_unit() const;

  // Normalised residuals: sum of squares = (weighted RMS %)^2. False if the parameters are
  // invalid for the model or the simulation diverged (r is then unspecified).
  bool residuals(const double* u, double* r) const;
  // residuals() at several points at once: ok[i] and r[i] (residual_count() values each) are
  // what residuals(u[i], r[i]) gives, bit for bit. With settings().lanes the points' records
  // share SIMD lanes, a vector holding one record across the points (the candidates of a
  // population or a Jacobian's columns: their lanes iterate and branch alike), which is the
  // speed-up over calling residuals() per point (docs/lanes.md, "Candidates in lanes").
  std::vector<char> residuals_batch(std::span<const double* const> u,
                                    std::span<double* const> r) const;
  // rms_pct() at several points at once (residuals_batch).
  std::vector<double> rms_pct_batch(const std::vector<std::vector<double>>& u) const;
  // sqrt(sum r^2): the weighted RMS error [%]; kPenalty when residuals() fails.
  double rms_pct(const std::vector<double>& u) const;
  // Why residuals() fails at u (the InputError or DivergenceError message), "" if it does not.
  std::string failure_reason(const std::vector<double>& u) const;
  static constexpr double kPenalty = 1e6;

  ModelSpec spec_at(const std::vector<double>& u) const;  // the start spec with u applied
  std::vector<ConditionFit> condition_fits(const std::vector<double>& u) const;
  std::vector<TargetFit> target_fits(const std::vector<double>& u) const;

  struct Impl;

 private:
  std::shared_ptr<const Impl> impl_;
};

// Simulates one measurement's excitation with the objective's rules (measured current as a
// table, or the biased sine) and returns y [um] (and B [T] if B_T != nullptr) at every
// measured sample time. Throws DivergenceError / InputError.
void simulate_measurement(const Model& m, const Measurement& meas, const ObjectiveSettings& s,
                          std::vector<double>& y_um, std::vector<double>* B_T = nullptr);

// =======================================================================================
// Synthetic measurements (validation, examples)
// =======================================================================================
struct SyntheticRequest {
  std::vector<double> temperatures_C{20, 45, 70};
  std::vector<double> currents_pp_A{6, 8};
  std::vector<double> frequencies_Hz{10, 100};
  double current_min_A = -3.0;
  double periods = 2.0;  // record length; the first period is not compared
  int samples_per_period = 200;
  double noise_pct = 1.0;  // Gaussian noise, sigma = this % of each condition's y p-p
  bool with_flux = true;
  double flux_noise_pct = 1.0;
  unsigned seed = 1;
  ObjectiveSettings objective;  // the same rules as the fit: an exact-model test
  // Record formats (docs/data.md): quasi-static records hold the biased sine's samples as
  // equilibria without a time axis; a field record's drive is the rod's applied field H_c
  // that the current produced (what a Hall probe or H-coil reads); a strain record's
  // response is the rod's strain in ppm; FirstSample writes the response relative to its
  // first sample (offset = first_sample), Fitted adds `response_offset` to it
  // (offset = fitted).
  bool quasi_static = false;
  DriveInput drive = DriveInput::Current;
  ResponseOutput response = ResponseOutput::Displacement;
  std::string rod;  // rod of the field / strain columns ("": the first rod)
  OffsetMode offset = OffsetMode::Absolute;
  double response_offset = 0.0;                             // [um or ppm], with OffsetMode::Fitted
  long precycles = 0;                                       // written as the records' precycles key
  InitialState initial_state = InitialState::Demagnetised;  // the records' initial_state key
};
// Every record it writes is one identify accepts (issue 19, item 6): the same settings rules
// (validate(ObjectiveSettings)), currents p-p in (0, 2000] A, frequencies in (0, 1 MHz],
// samples per period >= 8. Throws InputError naming the flag before any work.
MeasurementSet synthesize_measurements(const Model& truth, const SyntheticRequest& r);

// =======================================================================================
// Communicator: the processes of one identification (a single process, or MPI ranks)
// =======================================================================================
// Made by make_serial_communicator() or make_mpi_communicator(); the collectives identify()
// runs over it (sum, max, broadcast, ring, gather) are internal (src/identify/communicator.hpp).
class Communicator {
 public:
  virtual ~Communicator() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Ends every rank (MPI_Abort), or this process (exit) when it is alone.
  [[noreturn]] virtual void abort(int code) = 0;

 protected:
  Communicator() = default;
  Communicator(const Communicator&) = default;
  Communicator& operator=(const Communicator&) = default;
};

std::unique_ptr<Communicator> make_serial_communicator();
bool mpi_compiled();     // built with GMASIM_WITH_MPI
bool launched_by_mpi();  // the environment of mpirun / srun (OMPI_*, PMIX_RANK, PMI_RANK)
// MPI_Init_thread (funneled); MPI_Finalize when destroyed. Throws if not compiled with MPI.
std::unique_ptr<Communicator> make_mpi_communicator(int* argc, char*** argv);

// =======================================================================================
// identify()
// =======================================================================================
struct IdentifyProgress {
  std::string phase;                    // "ga", "refine" or "profile"
  int generation = 0, generations = 0;  // GA; refine: iteration; profile: parameter k of n
  std::string parameter;                // profile: the parameter being profiled
  double best_rms_pct = 0.0;
  long evaluations = 0;  // all ranks
  double evals_per_s = 0.0;
  double wall_s = 0.0;
};

// The island algorithms identify() knows (IdentifyOptions::algorithm), the one list the
// options' check, the archipelago's factory and the CLI's choices read.
inline constexpr std::string_view kIslandAlgorithms[] = {"sga", "de", "sade", "cmaes", "pso_gen"};
// "sga, de, sade, cmaes or pso_gen": the list for an error message.
std::string island_algorithm_list();
// True where `name` is one of kIslandAlgorithms.
bool is_island_algorithm(std::string_view name);

struct IdentifyOptions {
  std::string algorithm = "sga";  // one of kIslandAlgorithms (sga: the paper's multi-island GA)
  int islands = 4;                // fixed, not the core count: the islands are part of the search
  int population = 24;
  int generations = 60;   // total GA generations (a resumed run continues to this)
  int migrate_every = 5;  // generations between migrations along the island ring
  int migrants = 2;       // individuals per migration
  int mpi_every = 0;      // generations between champion exchanges over MPI (0: migrate_every)
  unsigned seed = 1;
  // Worker threads (0: the cores) evolving the islands and evaluating the first populations,
  // the refinement's and the profile's Jacobian batches; the result does not depend on it.
  int threads = 0;
  bool refine = true;  // Levenberg-Marquardt refinement of the champion
  int refine_iterations = 40;
  bool profile = true;  // profile-likelihood intervals where the linearisation cannot hold
  // Evaluations the profile stage may spend: -1 (default) as many as the search spent
  // (so the profile never costs more than the search), 0 no limit, else this many.
  long profile_evaluations = -1;
  double fd_step = 1e-4;  // central-difference step in u-space
  std::string checkpoint_path;
  int checkpoint_every = 10;  // generations
  std::string resume_path;
  ObjectiveSettings objective;
  // Called on rank 0 after every migration epoch, refinement iteration and profile solve.
  std::function<void(const IdentifyProgress&)> progress;
  // Polled between epochs / iterations: true stops cleanly (SIGINT). May be null.
  const std::atomic<bool>* stop = nullptr;
  Communicator* comm = nullptr;  // null: one process; else from make_*_communicator()
};

struct FittedParameter {
  std::string name, unit;
  ParamScale scale = ParamScale::Linear;
  double lower = 0, upper = 0, start = 0, value = 0;
  double std_error = 0;  // in the parameter's unit (delta method for log scale)
  // The linearised (Wald) 95 % interval from the Jacobian: value +- 1.96 sigma, or
  // value * exp(+-1.96 sigma) for log-scale parameters. Infinite when J^T J is singular in
  // the parameter's direction.
  double wald_low = 0, wald_high = 0;
  // Determined: the Wald interval is narrower than the bounds (log-scale parameters: in
  // ln|p|). Then the reported interval is the Wald interval; otherwise the data do not
  // constrain the parameter within its bounds, the linearisation is not valid over such a
  // range, and the reported interval is the bounds themselves.
  bool determined = true;
  double ci_low = 0, ci_high = 0;  // the reported 95 % confidence interval
  // "linearised" (the Wald interval, or the bounds if not determined), "profile" (profile
  // likelihood: for a parameter on a bound or whose Wald interval leaves the bounds; not
  // determined if it spans the bounds), "none" (interrupted run).
  std::string ci_method = "linearised";
  bool at_bound = false;  // the optimum lies on a bound
};

struct HistoryEntry {
  std::string phase;  // "ga", "refine"
  int step = 0;       // generation or refinement iteration
  long evaluations = 0;
  double best_rms_pct = 0.0, wall_s = 0.0, evals_per_s = 0.0;
};

// Model evaluations per stage of identify() (all ranks); they sum to IdentifyResult::evaluations.
struct StageEvaluations {
  long search = 0;      // the global search, with the start model's evaluation
  long refine = 0;      // Levenberg-Marquardt (including refits from a point the profile found)
  long covariance = 0;  // the Jacobians of the linearised intervals
  long profile = 0;     // the profile likelihood
  long profile_budget = -1;  // the profile's allowance (-1: no limit)
  // Wall time [s] of each stage (rank 0's clock; the search's includes the start model's
  // evaluation and, on a resumed run, only this run's part).
  double search_s = 0, refine_s = 0, covariance_s = 0, profile_s = 0;
  // Results copied instead of simulated again: a point equal to one just evaluated (not in
  // the counts above).
  long reused = 0;
};

struct IdentifyResult {
  ModelSpec spec;  // the start spec with the fitted values
  std::vector<FittedParameter> parameters;
  std::vector<double> unit_optimum;
  double start_rms_pct = 0, ga_rms_pct = 0, rms_pct = 0;
  std::vector<ConditionFit> conditions;
  std::vector<TargetFit> targets;
  std::vector<std::vector<double>> correlation;  // n x n, from the Jacobian at the optimum
  double residual_sigma = 0;                     // sqrt(sum r^2 / (m - n))
  std::size_t residual_count = 0;
  bool covariance_ok = false;
  std::string covariance_note;
  std::vector<HistoryEntry> history;
  long evaluations = 0;  // all ranks
  StageEvaluations stage_evaluations;
  // The stage that found the written point: "search" (the GA's best, or the start),
  // "refinement" (Levenberg-Marquardt improved it) or "profile" (a profile-likelihood refit
  // found a lower error; the point was then refined and its intervals recomputed).
  std::string best_found_by = "search";
  double wall_s = 0, ga_evals_per_s = 0;
  int generations_done = 0, ranks = 1, islands = 0, population = 0;
  std::string algorithm;
  bool interrupted = false, resumed = false;
  std::string refine_summary;
  std::vector<std::string> notes;
};

// Runs the whole identification. With a communicator of size R every rank must call it with
// the same arguments; every rank returns the same parameters, intervals and history, and
// rank 0 also the per-condition and target fits (for the report). Throws InputError.
IdentifyResult identify(const ModelSpec& start, const MeasurementSet& data, const FitSpec& fit,
                        const IdentifyOptions& options);

// =======================================================================================
// Outputs
// =======================================================================================
struct FitProvenance {
  std::string command;                     // the command line
  std::string data;                        // manifest path
  std::string fit;                         // fit spec source
  std::string report_dir;                  // where the fit report is
  std::string start_model;                 // start model label
  std::vector<std::string> fitted_claims;  // fitted_claims(the fit spec): the [calibration] table
};

// The start model's text with each fitted value replaced and its provenance comment set;
// a header names the data, the command and the fit. Re-parsed and checked before return.
// The output describes this one run: when the start is itself an identify output, its
// header and its 'identified:' comments are replaced, not nested (the original provenance
// of each value is kept).
std::string fitted_model_toml(const std::string& start_text, const ModelSpec& start,
                              const IdentifyResult& r, const FitProvenance& p);
std::string fit_report_json(const IdentifyResult& r, const FitProvenance& p);
std::string fit_report_markdown(const IdentifyResult& r, const FitProvenance& p);
std::string convergence_csv(const IdentifyResult& r);
// "search N, refinement N, covariance N, profile N of M allowed": the evaluations per stage.
std::string stage_text(const StageEvaluations& se);

}  // namespace gmasim
