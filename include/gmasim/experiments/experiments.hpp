// The paper's experiments (sections 4.4, 4.5, 5) as library functions returning result
// structs. The CLI, the Python module and `gmasim reproduce` are thin shells over these.
// How each experiment is measured: docs/experiments.md.
#pragma once

#include <complex>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "gmasim/mechanics/mechanics.hpp"
#include "gmasim/mechanics/state_space.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

// Progress callback: (points done, points total). Called from worker threads, serialised.
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

// Threads used for `requested` (0: all hardware threads), never more than `work` items.
int resolve_thread_count(int requested, std::size_t work);

// ---------------------------------------------------------------------------------------
// Sweep: temperature x current peak-to-peak x frequency (Fig. 12-14).
// ---------------------------------------------------------------------------------------
struct SweepRequest {
  std::vector<double> temperatures_C{20, 30, 40, 50, 60, 70};
  std::vector<double> currents_pp_A{6, 8, 10, 12};
  std::vector<double> frequencies_Hz{10};
  double reference_temperature_C = 20.0;  // relative changes are against this temperature
  double current_min_A = -3.0;            // Fig. 11
  double periods = 3.0;
  double dt_s = 0.0;  // 0: auto_dt
  int threads = 0;    // 0: all hardware threads
  Freeze freeze;
  // Grid points advance together in SIMD lanes (gmasim/simulate/lanes.hpp) where the model
  // allows; false: one scalar simulate() per point (the reference the benchmarks compare with).
  bool lanes = true;
};

struct SweepPoint {
  double temperature_C = 0, current_pp_A = 0, frequency_Hz = 0;
  Metrics metrics;
  // Relative change against the reference temperature at equal current and frequency [%].
  double stroke_change_pct = 0, hysteresis_change_pct = 0, B_pp_change_pct = 0;
  bool diverged = false;
  std::string error;
};

struct SweepResult {
  std::vector<SweepPoint> points;  // order: temperature-major, then current, then frequency
  // Reference-temperature runs that are not grid points (same order: current, frequency).
  std::vector<SweepPoint> reference_points;
  double wall_time_s = 0;
  int threads = 0;
  long simulations = 0;  // grid points + extra reference runs
};

// Throws InputError for an empty grid, a frequency <= 0, a negative current, a temperature
// at/above T_c. A diverged point is recorded (diverged, error) and the sweep continues.
// Deterministic whatever the thread count: every point writes its own slot.
SweepResult run_sweep(const Model& m, const SweepRequest& r, const ProgressFn& progress = {});

// ---------------------------------------------------------------------------------------
// Frequency response current -> displacement (Fig. 15) and the modes of eq. (15).
// ---------------------------------------------------------------------------------------
// The magnetic state the small-signal measurement starts from (docs/experiments.md):
// Anhysteretic: M_irr = M_an at the bias (the state a decaying AC excitation about the
// bias leaves; small sines about it are reversible to first order); InitialCurve: the
// virgin magnetisation curve of make_state() (the JA minor loop then creeps for
// ~k/(2 dH) cycles, so a stepped sine does not match the linearisation).
enum class BiasState { Anhysteretic, InitialCurve };

struct FrfRequest {
  std::vector<double> temperatures_C{20, 70};
  double f_min_Hz = 1.0, f_max_Hz = 5000.0;
  int points = 40;            // log-spaced
  double bias_A = 1.0;        // DC bias current (the middle of the 8 A sine of Fig. 11)
  double amplitude_A = 1e-4;  // stepped-sine amplitude (small signal: docs/experiments.md)
  // Stepped sine: settle for at least settle_periods periods and at least 10 time constants
  // (slowest eddy lag or mechanical decay), then take the first harmonic over
  // measure_periods whole periods.
  int settle_periods = 2, measure_periods = 2;
  // Stepped sine time step: at least this many steps per period and at most 10 us. The
  // time stepping adds a phase lag of O(dt) (0.2 deg at 200 steps per period, 0.04 deg at
  // 1000, measured at 0.4-5 kHz), so the default is finer than the simulate rule's floor.
  int min_steps_per_period = 1000;
  bool stepped_sine = true, small_signal = true;
  BiasState bias_state = BiasState::Anhysteretic;
  int threads = 0;  // stepped-sine frequencies run in parallel
  // The stepped-sine grid's points advance together in SIMD lanes (gmasim/simulate/lanes.hpp)
  // where the model allows; false: one scalar run per point (the reference the lanes are
  // compared with).
  bool lanes = true;
  // Stepped sine: golden-section evaluations in ln f around the largest |Y/I| of the grid (the
  // peak refined between its grid neighbours, the points merged into the curve); 0: off.
  int peak_refinements = 12;
};

// Settles the actuator at a DC bias current (make_state, then `bias_state`, then DC steps
// until H, M and x are at rest). Returns the state; throws DivergenceError.
State settle_at_bias(const Model& m, const Conditions& c, double bias_A, BiasState bias_state);

// The coil's incremental inductance at a DC bias (issue 39 item 1; src/experiments/
// inductance.cpp): L = dPsi/dI, Psi = sum_b N_b phi_b the coil's flux linkage, on the minor loop
// at the bias -- from the anhysteretic state there (settle_at_bias), the current steps to bias
// +- delta_A (and +- 2 delta_A) and is held until the eddy lag has died out; central differences,
// Richardson-combined. Reported (gmasim
// model show), not used by the step. Throws DivergenceError, InputError (delta_A <= 0).
struct CoilInductance {
  double temperature_C = 0, bias_A = 0, delta_A = 0;
  double inductance_H = 0;   // dPsi/dI [H], 2 L(delta) - L(2 delta) (Richardson)
  double first_order_H = 0;  // the plain central difference over +-delta [H]
  double linkage_Wb = 0;     // Psi at the bias [Wb-turns]
};
CoilInductance coil_inductance(const Model& m, double temperature_C, double bias_A,
                               double delta_A = 1e-5);

struct FrfCurve {
  double temperature_C = 0;
  std::vector<double> f_Hz;
  // Stepped sine (time-domain simulation, first harmonic of y over the current) [um/A, deg]
  std::vector<double> stepped_mag_um_per_A, stepped_phase_deg;
  // Small-signal linearisation about the bias point [um/A, deg]
  std::vector<double> linear_mag_um_per_A, linear_phase_deg;
  double first_resonance_Hz = 0;  // largest peak of |Y/I| (linear model) in the band, 0 if none
  double first_resonance_mag_um_per_A = 0;  // |Y/I| there (0 if no peak)
  // The same search on the linear model continued above f_max, up to twice the highest
  // mode (0 if |Y/I| has no local maximum there either).
  double linear_peak_extended_Hz = 0, linear_peak_search_max_Hz = 0;
  double bandwidth_3dB_Hz = 0;  // first f where |Y/I| falls 3 dB below its low-f value
  // The same two numbers from the stepped sine (0 if none / not run).
  double stepped_first_resonance_Hz = 0, stepped_bandwidth_3dB_Hz = 0;
  double max_mismatch_pct = 0;              // max |stepped - linear| / |linear| over the band [%]
  std::vector<double> mode_frequencies_Hz;  // eq. (15) eigen-analysis at the bias point
  std::vector<double> mode_damping_ratios;
  double static_gain_um_per_A = 0;  // |Y/I| of the linear model at 0 Hz
  double y_bias_um = 0;
  std::vector<double> eddy_tau_ms;  // per rod at the bias point
  double wall_time_s = 0;
  // Small or large signal (docs/experiments.md, "Small or large signal"): the stimulus is small
  // up to small_signal_limit_A (every rod's field excursion within 10 % of its reversible range
  // c k / (1 - c), eq. 9); large_signal: a stepped sine above it. The markers (first resonance,
  // bandwidth, the -3 dB reference gain = |Y/I| at f_min) come from the data the figure draws:
  // markers_from "stepped sine" when the stimulus is large or the linearisation is off,
  // "linearisation" otherwise.
  double small_signal_limit_A = 0;
  bool large_signal = false;
  std::string markers_from = "linearisation";
  double reference_gain_um_per_A = 0;
};

struct FrfResult {
  std::vector<FrfCurve> curves;
  // Fig. 15, for the report: the paper's first resonance and the bandwidth it exceeds
  // (run_frf reads them from data/claims.toml: claims first_resonance and bandwidth).
  double paper_first_resonance_Hz = 0.0, paper_bandwidth_Hz = 0.0;
};

// Throws InputError for an empty temperature list, f_min <= 0, f_max <= f_min, fewer than
// 2 points, a non-positive amplitude, settle/measure periods < 1, or a temperature >= T_c.
FrfResult run_frf(const Model& m, const FrfRequest& r, const ProgressFn& progress = {});

// First harmonic of y and i over whole periods: (sum y e^{-jwt}) / (sum i e^{-jwt}).
std::complex<double> first_harmonic_ratio(const std::vector<double>& t_s,
                                          const std::vector<double>& y,
                                          const std::vector<double>& i, double f_Hz);

// Peak and -3 dB bandwidth of a magnitude curve on an increasing frequency grid: the
// resonance is the largest interior local maximum (parabola-refined in log f; 0 if the
// curve has none, e.g. monotone roll-off); the bandwidth is the first crossing of |Y(f_0)|/sqrt 2,
// interpolated in log f (0 if never crossed).
double find_resonance_Hz(const std::vector<double>& f_Hz, const std::vector<double>& mag);
double find_bandwidth_3dB_Hz(const std::vector<double>& f_Hz, const std::vector<double>& mag);

// The linearisation's first resonance and -3 dB bandwidth [Hz], as run_frf() marks them on a
// curve without the stepped sine: |Y(f)| on a 4000-point log grid over [f_min_Hz, f_max_Hz]
// (find_resonance_Hz, find_bandwidth_3dB_Hz), its points computed only where those rules can
// pick one (a scan of every 8th point, 501 of them, then windows of 9 to 33 points around its
// peaks, notches, first crossing and the oscillators' natural frequencies in the band;
// src/experiments/frf_markers.cpp).
// run_frf's markers and linear_frf_markers() of the same bias point are the same numbers.
struct LinearFrfMarkers {
  double first_resonance_Hz = 0, bandwidth_3dB_Hz = 0;
};
LinearFrfMarkers linear_frf_markers(const SmallSignalModel& lin, double f_min_Hz, double f_max_Hz);
// At temperature T_C and DC bias bias_A with FrfRequest's default band and bias state: the
// cost of one settle_at_bias() and the dense grid, without the rest of run_frf's curve (the
// identify objective's frf_peak_Hz and bandwidth_Hz targets).
LinearFrfMarkers linear_frf_markers(const Model& m, double T_C, double bias_A);

// ---------------------------------------------------------------------------------------
// Closed-loop tracking with the paper's PID (Fig. 16).
// ---------------------------------------------------------------------------------------
// Units (the paper does not give them; docs/experiments.md, "Closed-loop tracking"): the
// error e is in um and the controller output u in A, added to the bias current. kp [A/um];
// ki and kd [A/um] are per-sample gains at reference_rate_Hz (10 kHz), i.e. continuous
// gains Ki = ki * reference_rate [A/(um s)] and Kd = kd / reference_rate [A s/um].
struct PidGains {
  double kp = 0.2, ki = 0.03, kd = 0.007;  // units: docs/experiments.md
  double reference_rate_Hz = 10000.0;      // the sample rate at which ki, kd are per sample
};

// Discrete positional PID with conditional-integration anti-windup:
//   u_k = kp e_k + Ki Ts sum_{j<=k} e_j + Kd (e_k - e_{k-1}) / Ts
// with Ki = ki * reference_rate [A/(um s)] and Kd = kd / reference_rate [A s/um], so at
// the reference rate u_k = kp e_k + ki sum e_j + kd (e_k - e_{k-1}) and the continuous
// controller does not change with the sample rate. The output is clipped to
// [u_min, u_max]; while clipped, the sum does not grow in the clipping direction.
class Pid {
 public:
  // The coefficients of u_k at sample_rate_Hz: kp, Ki Ts = ki f_ref/f_s, Kd/Ts = kd f_s/f_ref
  // (the update below; pid_loop_margins analyses the same loop).
  struct PerSample {
    double kp, ki, kd;
  };
  static PerSample per_sample(const PidGains& g, double sample_rate_Hz);
  Pid(const PidGains& g, double sample_rate_Hz, double u_min, double u_max);
  double update(double error);  // one sample; returns u
  void reset();
  // New output limits from the next update on (the inverse feed-forward moves them with its
  // current, so that anti-windup acts where the coil current clips).
  void set_limits(double u_min, double u_max);
  double integral_sum() const { return sum_; }

 private:
  double kp_, ki_s_, kd_s_;  // per-sample coefficients at this sample rate
  double u_min_, u_max_;
  double sum_ = 0.0, e_prev_ = 0.0;
  bool first_ = true;
};

// The PID loop's stability margins at one temperature (issue 40 item 3; src/experiments/
// loop_margins.cpp): the linearised plant sampled as `track` drives it (current set at each
// sample, reached over the first plant step of plant_dt_s, held; the sensor read at the sample),
// the Pid above with its coefficients at sample_rate_Hz, the amplifier's A per unit, the error
// in um. Gain margin [dB] at the phase crossover (phase -180 deg), phase margin [deg] at the gain
// crossover (|L| = 1), the smallest of each from 0.1 Hz to the Nyquist frequency (inf where
// there is no crossing); the closed loop's largest pole magnitude (< 1: stable, the linear loop
// without clipping) and that pole's frequency [Hz].
struct LoopMargins {
  double temperature_C = 0;
  double gain_margin_dB = std::numeric_limits<double>::infinity(), phase_crossover_Hz = 0;
  double phase_margin_deg = std::numeric_limits<double>::infinity(), gain_crossover_Hz = 0;
  double spectral_radius = 0, dominant_Hz = 0;
  bool stable = false;
};
LoopMargins pid_loop_margins(const StateSpace& plant, const PidGains& g, double sample_rate_Hz,
                             double plant_dt_s, double amplifier_A_per_unit);

// Temperature feed-forward (gmasim compensate, include/gmasim/experiments/compensate.hpp): at
// operating temperature T the coil current is
//   i = bias + g(T) (u_PID + (r(t) - y_bias) / K_ref),   clipped to +-current_limit_A,
// where g(T) interpolates (temperatures_C, gains) linearly (held beyond the ends) and K_ref
// is the static gain dy/di at the bias [um/A] (0: no reference feed-forward, the schedule
// only scales the PID). Off while `gains` is empty.
struct TemperatureFeedforward {
  std::vector<double> temperatures_C, gains;
  double static_gain_um_per_A = 0.0;
  bool enabled() const { return !gains.empty(); }
  double gain_at(double temperature_C) const;  // 1 when off
};

// Inverse-model feed-forward (gmasim/experiments/feedforward.hpp): the current the model at the
// loop's temperature says produces the reference, added ahead of the PID:
//   i = clip(i_ff(t) + a u_PID, +-current_limit_A),  the PID's limits following i_ff.
// Off unless `enabled`; not combined with the temperature feed-forward.
struct InverseFeedforwardRequest {
  bool enabled = false;
  double band_Hz = 500.0;  // fit band of the linear part's inverse
  bool dynamic = true;     // false: the quasi-static inverse alone
};

struct TrackRequest {
  std::vector<double> temperatures_C{20, 30, 40, 50, 60, 70};
  std::vector<double> amplitudes_um{10, 20};
  std::vector<double> frequencies_Hz{10, 100};
  PidGains gains;
  double sample_rate_Hz = 10000.0;  // controller and sensor sample rate
  double bias_A = 1.0;              // coil bias the controller output is added to
  double current_limit_A = 10.0;    // amplifier saturation (+-)
  // The amplifier between the PID and the coil: coil current per unit of controller output
  // [A/unit], so kp is kp * this [A/um]. The paper prints the gains, not the amplifier: with
  // 1 A/unit the calibrated plant (7 um/A at 20 degC, the design's 100 um at 12 A) rings at the
  // sampling Nyquist frequency, against Fig. 16's stable loop at every temperature; 0.5 keeps
  // it stable from 20 to 70 degC (docs/experiments.md, "Closed-loop tracking").
  double amplifier_A_per_unit = 0.5;
  double sensor_noise_um = 0.0;  // RMS white noise of the displacement sensor
  std::uint64_t noise_seed = 1;  // seed of the sensor-noise generator (per point)
  double periods = 4.0;          // errors over the last period
  double dt_s = 0.0;             // plant step; 0: <= 10 us, <= T/2000, divides 1/fs
  int threads = 0;
  TemperatureFeedforward feedforward;
  InverseFeedforwardRequest inverse;
  // Your controller in the loop (issue 40, item 4), in place of the PID: called once per
  // sample with the reference and the measured displacement [um] (noise included) and the
  // temperature [degC]; it returns the coil current [A], which the amplifier clips to
  // +-current_limit_A (gains, amplifier scaling and bias are then the controller's own). A
  // non-finite current stops the run with an InputError naming the sample. controller_reset,
  // if given, is called before each run (a run per temperature, amplitude and frequency, in
  // that order). With a controller the runs are sequential (it may hold state) and neither
  // feed-forward may be set; the margins table stays empty (it is the PID's).
  std::function<double(double reference_um, double measured_um, double temperature_C)> controller;
  std::function<void()> controller_reset;
};

struct TrackPoint {
  double temperature_C = 0, amplitude_um = 0, frequency_Hz = 0;
  double error_rms_um = 0, error_peak_um = 0;
  double error_rms_pct = 0;                     // RMS error / amplitude [%]
  double error_change_pct = 0;                  // RMS error vs the first temperature of the request
  double y_bias_um = 0;                         // operating point the reference is centred on
  double current_min_A = 0, current_max_A = 0;  // coil current over the last period
  bool saturated = false;                       // the current hit +-current_limit_A
  double feedforward_gain = 1.0;                // g(T) of the temperature feed-forward
  // The inverse feed-forward's current over the whole run (0 when it is off) [A].
  double feedforward_min_A = 0, feedforward_max_A = 0;
  // The sampled error's sign changes per sample over the last period (about 2 f / f_s for a
  // loop that tracks; about 1 for one that rings at the Nyquist frequency), the frequency they
  // imply, alternation x f_s / 2 [Hz], and whether it exceeds kLimitCycleAlternation.
  double error_alternation = 0, error_oscillation_Hz = 0;
  bool limit_cycle = false;
  bool diverged = false;
  std::string error;
};

// TrackPoint::limit_cycle: the sampled error changes sign at more than half the samples of the
// last period, i.e. it oscillates above a quarter of the sample rate.
inline constexpr double kLimitCycleAlternation = 0.5;

struct TrackResult {
  std::vector<TrackPoint> points;  // order: temperature, amplitude, frequency
  // The PID loop's margins at each temperature of the request (pid_loop_margins about the
  // bias; with the temperature feed-forward the loop gain includes its g(T)).
  std::vector<LoopMargins> margins;
  TimeSeries example;  // one run (first point): t_s, reference_um, y_um, current_A, error_um
  double plant_dt_s = 0;
  double wall_time_s = 0;
  int threads = 0;
};

// Throws InputError if the sample rate is below twice a reference frequency, for an empty
// list, a frequency <= 0, an amplitude <= 0, a temperature >= T_c, a non-positive limit.
TrackResult run_track(const Model& m, const TrackRequest& r, const ProgressFn& progress = {});

// ---------------------------------------------------------------------------------------
// Ablation (Fig. 20): freeze one temperature law at 20 degC, one at a time.
// ---------------------------------------------------------------------------------------
struct AblateRequest {
  double temperature_C = 70.0;
  std::vector<double> frequencies_Hz{10, 200};
  double current_pp_A = 6.0;
  double periods = 3.0;
  double current_min_A = -3.0;
  int threads = 0;
  // The runs advance together in SIMD lanes (gmasim/simulate/lanes.hpp) where the model allows;
  // false: one simulate() per run (the reference the lanes are compared with).
  bool lanes = true;
};

struct AblationRow {
  std::string law;  // "mu_G", "rho_G", "M", "E_G", "E_t" (and "F_pm", "geometry", "all")
  double frequency_Hz = 0;
  double error_rms_um = 0;   // RMS of y_frozen - y_full over the last period
  double error_peak_um = 0;  // peak |y_frozen - y_full| over the last period
  double error_pct_of_stroke = 0;
  double stroke_um = 0, hysteresis_um = 0;                  // of the frozen model
  double stroke_change_pct = 0, hysteresis_change_pct = 0;  // frozen vs full
  bool diverged = false;
  std::string error;
};

struct AblateResult {
  std::vector<AblationRow> rows;  // frequency-major, laws in the order of ablation_laws()
  std::vector<Metrics> full;      // the full model, one per frequency
};

// The ablated laws, their Freeze switches and what they freeze.
struct AblationLaw {
  std::string name, description;
  Freeze freeze;
};
std::vector<AblationLaw> ablation_laws();

AblateResult run_ablate(const Model& m, const AblateRequest& r);

// ---------------------------------------------------------------------------------------
// Parameters against temperature (Fig. 19) and stroke retention (Fig. 18).
// ---------------------------------------------------------------------------------------
struct ParamsVsTemperatureRequest {
  std::vector<double> temperatures_C{20, 40, 60, 80, 100, 120, 150};
  double current_pp_A = 8.0, frequency_Hz = 10.0;  // the operating point of Fig. 19
  std::vector<double> retention_currents_pp_A{6, 8, 10, 12};
  double periods = 3.0;
  double dt_s = 0.0;  // 0: auto_dt (gmasim reproduce gives claim_dt's step)
  double current_min_A = -3.0;
  int threads = 0;
  // The runs advance together in SIMD lanes where the model allows (AblateRequest::lanes).
  bool lanes = true;
};

struct ParamsVsTemperatureRow {
  double temperature_C = 0;
  std::string rod;
  double mu_r_mean = 0;       // mu_G / mu0, mean over the last period
  double rho_ohm_m = 0;       // eq. (8)
  double M_peak_A_per_m = 0;  // peak magnetisation over the last period
  double MsT_A_per_m = 0;     // eq. (4)
  double E_G_mean_GPa = 0;    // eq. (13), mean over the last period
  double E_t_GPa = 0;         // eq. (19)
  // Changes vs the first temperature of the request, same rod [%] (Fig. 19f).
  double mu_r_change_pct = 0, rho_change_pct = 0, M_peak_change_pct = 0, E_G_change_pct = 0,
         E_t_change_pct = 0;
};

struct RetentionRow {
  double current_pp_A = 0, temperature_C = 0, stroke_um = 0, hysteresis_um = 0;
  double stroke_retention_pct = 0;  // vs the first temperature
  double hysteresis_retention_pct = 0;
};

struct ParamsVsTemperatureResult {
  std::vector<ParamsVsTemperatureRow> rows;
  std::vector<RetentionRow> retention;
};

ParamsVsTemperatureResult run_params_vs_temperature(const Model& m,
                                                    const ParamsVsTemperatureRequest& r);

// ---------------------------------------------------------------------------------------
// Thermal expansion of the stack, eq. (21).
// ---------------------------------------------------------------------------------------
struct ThermalExpansionResult {
  double um_per_C = 0;  // d x_T / d T
  double rod_um_per_C = 0, magnetizer_um_per_C = 0, output_rod_um_per_C = 0,
         sleeve_um_per_C = 0;  // the four terms (sleeve counted negative in the sum)
  // The paper's values, model and measured (from data/claims.toml: claims thermal_model and
  // thermal_measured).
  double paper_model_um_per_C = 0.0, paper_measured_um_per_C = 0.0;
};

ThermalExpansionResult thermal_expansion_coefficient(const Model& m);

// ---------------------------------------------------------------------------------------
// Reports: one table per result (CSV: one row per point, column names with units) and a
// JSON document with the same data (src/experiments/report.cpp builds them; table_csv and
// report_json of gmasim/io/io.hpp write them).
// ---------------------------------------------------------------------------------------
struct Cell {
  double number = 0.0;
  std::string text;
  bool is_text = false;
  bool is_bool = false;                            // text "true"/"false", a JSON boolean
  Cell(double v) : number(v) {}                    // NOLINT
  Cell(int v) : number(static_cast<double>(v)) {}  // NOLINT
  Cell(bool v) : text(v ? "true" : "false"), is_text(true), is_bool(true) {}  // NOLINT
  Cell(std::string s) : text(std::move(s)), is_text(true) {}                  // NOLINT
  Cell(const char* s) : text(s), is_text(true) {}                             // NOLINT
};

struct Table {
  std::string name;  // "points", "curves", ...
  std::vector<std::string> columns;
  std::vector<std::vector<Cell>> rows;
};

struct Report {
  std::string experiment;                          // "sweep", "frf", ...
  std::vector<std::pair<std::string, Cell>> meta;  // settings and summary numbers
  std::vector<Table> tables;
};

Report sweep_report(const Model& m, const SweepRequest& req, const SweepResult& res);
Report frf_report(const Model& m, const FrfRequest& req, const FrfResult& res);
Report track_report(const Model& m, const TrackRequest& req, const TrackResult& res);
Report ablate_report(const Model& m, const AblateRequest& req, const AblateResult& res);
Report params_report(const Model& m, const ParamsVsTemperatureRequest& req,
                     const ParamsVsTemperatureResult& res);
Report thermal_report(const Model& m, const ThermalExpansionResult& res);

// gmasim linearize (src/experiments/linearize.cpp): the plant settled at the bias
// (settle_at_bias, anhysteretic), linearised (linearise) and written as a state space
// (gmasim/mechanics/state_space.hpp); its report: the states with their units, A, B, C, D, the
// poles and the zeros of y.
StateSpace linearize_plant(const Model& m, double temperature_C, double bias_A);
StateSpace linearize_plant(const Model& m, const Conditions& c, double bias_A);  // at c's T
// The large-signal companion of the state space (issue 40 item 1): the describing function of
// the plant at a current amplitude about the bias -- the first harmonic of y over that of a
// sine i = bias + amplitude sin(2 pi f t), from the settled anhysteretic bias state, by the
// FRF's stepped sine (its settling, measuring periods and time step; gmasim frf --amplitude) --
// beside the state space's small-signal response at each frequency.
struct DescribingPoint {
  double f_Hz = 0;
  double gain_um_per_A = 0, phase_deg = 0;                            // at the amplitude
  double small_signal_gain_um_per_A = 0, small_signal_phase_deg = 0;  // the state space's
};
// Throws InputError for an amplitude <= 0 or beyond the coil's limit, an empty or non-positive
// frequency list; DivergenceError naming --amplitude when a run diverges.
std::vector<DescribingPoint> describing_function(const Model& m, const StateSpace& ss,
                                                 double amplitude_A,
                                                 const std::vector<double>& f_Hz, int threads = 0);
// The describing function as a table (frequency_Hz, gain_um_per_A, phase_deg,
// small_signal_gain_um_per_A, small_signal_phase_deg, gain_ratio): the report's, and Python's.
Table describing_function_table(const std::vector<DescribingPoint>& df);
// The report; with `df`, a table "describing_function" at that amplitude too.
Report linearize_report(const Model& m, const StateSpace& ss,
                        const std::vector<DescribingPoint>* df = nullptr, double amplitude_A = 0);

}  // namespace gmasim
