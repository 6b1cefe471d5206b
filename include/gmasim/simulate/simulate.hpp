// Excitations, the fixed-step run loop, recording and metrics.
#pragma once

#include <functional>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gmasim/model/model.hpp"

namespace gmasim {

// ---------------------------------------------------------------------------------------
// Excitation current waveforms [A] driving the coil's N turns.
// ---------------------------------------------------------------------------------------
enum class WaveformKind { BiasedSine, DC, Step, Chirp, Table };

struct Waveform {
  WaveformKind kind = WaveformKind::BiasedSine;
  // BiasedSine (Fig. 11): i(t) = min_A + pp_A/2 (1 - cos 2 pi f t); starts at its minimum.
  double min_A = -3.0;
  double pp_A = 8.0;
  double frequency_Hz = 10.0;
  // DC: level_A. Step: level_A before step_time_s, step_to_A after.
  double level_A = 0.0;
  double step_to_A = 0.0;
  double step_time_s = 0.0;
  // Chirp: offset_A + amplitude_A sin(phase), frequency swept linearly f0 -> f1 over
  // duration_s (the run length).
  double offset_A = 0.0, amplitude_A = 0.0, f0_Hz = 1.0, f1_Hz = 100.0, duration_s = 1.0;
  // Table (CSV t_s,current_A): linear interpolation, held constant past the ends.
  std::vector<double> table_t_s, table_current_A;
  std::string table_source;
  // Table: the period the file declares (a "# period_s = P" line before its header), 0 if none:
  // the metrics are then over the run's last P seconds, as a biased sine's over its last period.
  double table_period_s = 0.0;

  double current_at(double t_s) const;  // [A]
  // BiasedSine's current [A] at a time whose cos(2 pi f t) is given: current_at's formula, for
  // callers that take the cosine once for many waveforms of one frequency (simulate_lanes).
  double biased_sine_from_cos(double cos_2pi_f_t) const {
    return min_A + 0.5 * pp_A * (1.0 - cos_2pi_f_t);
  }
  bool periodic() const { return kind == WaveformKind::BiasedSine; }
  double period_s() const { return 1.0 / frequency_Hz; }
};

Waveform biased_sine(double pp_A, double frequency_Hz, double min_A = -3.0);

// Linear interpolation of y(x) at `at` over increasing x (same length, not empty), held at
// the end values beyond the ends. Used by Table waveforms and gain schedules.
double interpolate_held(const std::vector<double>& x, const std::vector<double>& y, double at);

// ---------------------------------------------------------------------------------------
// Run settings and results.
// ---------------------------------------------------------------------------------------
// Self-heating (gmasim/model/self_heating.hpp): the run starts with coil, rods and housing at
// temperature_C; every thermal step the losses of that interval heat the network and the
// Conditions are recomputed at the rods' new temperature.
struct SelfHeatingSettings {
  bool enabled = false;
  double thermal_step_s = 0.0;  // 0: whole periods spanning >= 0.1 s (periodic), else 0.1 s
  double ambient_C = std::numeric_limits<double>::quiet_NaN();  // NaN: temperature_C
};

struct SimulationSettings {
  double temperature_C = 20.0;  // start temperature of every node (self-heating) or the fixed one
  // Book the energy ledgers (gmasim/model/energy.hpp) and the coil's terminal quantities over the
  // metrics window (Result::energy, Result::coil). `gmasim simulate`, Python's simulate() and
  // `model check` turn it on; self-heating books them whatever this says (its losses come from
  // the ledger). Off by default for the experiments that run many simulations: it solves every
  // branch of the circuit and integrates each oscillator's power at every step.
  bool energy_ledger = false;
  Waveform waveform;
  double periods = 3.0;     // run length for periodic waveforms
  double duration_s = 0.0;  // run length for the others (Table: its last time if 0)
  double dt_s = 0.0;        // 0: the automatic rule, auto_dt()
  int record_every = 1;     // decimation of the recorded time series
  // The metrics' window for a waveform that is not a biased sine: the run's last
  // metrics_window_s seconds; 0: a table's declared period (table_period_s), else the whole
  // run. A biased sine's metrics are over its last period (a window > 0 is refused there).
  double metrics_window_s = 0.0;
  Freeze freeze;
  SelfHeatingSettings self_heating;
  // Called with (steps done, steps in all) about every 1 % of the run (never inside step()).
  std::function<void(std::size_t, std::size_t)> progress;
};

// The documented time-step rule (docs/model.md, "Time step"): a periodic run takes
// kStepsPerPeriod steps per period, capped at kMaxDt_s; others use kMaxDt_s, or for
// chirps 1/(kStepsPerPeriod f1) if smaller.
inline constexpr double kStepsPerPeriod = 2000.0;
inline constexpr double kMaxDt_s = 10e-6;
double auto_dt(const Waveform& w);

// The claims' time step (issue 37, "one numerics"): the rule above with its cap at
// kClaimMaxDt_s instead of kMaxDt_s, so 25 us at 10 Hz and auto_dt()'s step from 50 Hz up.
// `gmasim reproduce`'s 10 Hz sweep and 20-150 degC runs and `gmasim identify`'s scalar
// targets take it, so that the fit and the score compute every claim alike. Its error on each
// claim is below a tenth of the claim's tolerance (docs/model.md, "The claims' time step"),
// and 25 us stays below the trapezoidal eddy field's ringing limit 2 mu0 kappa (42.8-112 us at
// 20 degC, docs/model.md's time-step table; rod 1's falls to about 28 us by 150 degC as rho_G
// rises 54 %).
inline constexpr double kClaimMaxDt_s = 25e-6;
double claim_dt(const Waveform& w);

// A named set of equally long columns (SI values, names carry units: "y_um").
struct TimeSeries {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
  const std::vector<double>& column(const std::string& name) const;  // throws
  std::size_t rows() const { return columns.empty() ? 0 : columns[0].size(); }
};

struct Metrics {
  double window_start_s = 0, window_end_s = 0;  // the last whole period
  double stroke_um = 0;                         // peak-to-peak of y
  double hysteresis_um = 0;                     // max |y_rising - y_falling| at equal current
  double B_pp_T = 0;                            // peak-to-peak of B
  double y_mean_um = 0;
};

// The table of Metrics (issue 21, item 3), as kFreezeSwitches: one row per field, in the order of
// the metrics.json object and the Python dict. From it: metrics.json (src/io/output.cpp), the
// `gmasim simulate` summary (the rows with a label; `note`'s {} is the metrics window) and the
// Python dict (python/src/module.cpp metrics_dict, gmasim._gmasim.metric_rows()).
struct MetricRow {
  std::string_view name;  // JSON / Python key, unit-suffixed
  std::string_view unit;
  double Metrics::*member;
  std::string_view label;  // the CLI summary's label ("" : not printed there)
  int precision;           // the CLI summary's decimals
  std::string_view note;   // the CLI summary's note ("{}" : the metrics window)
};
inline constexpr MetricRow kMetricRows[] = {
    {"stroke_um", "um", &Metrics::stroke_um, "stroke", 3, "(peak-to-peak of y {})"},
    {"hysteresis_um", "um", &Metrics::hysteresis_um, "hysteresis", 3,
     "(widest rising/falling gap at equal current)"},
    {"B_pp_T", "T", &Metrics::B_pp_T, "B p-p", 4, "(induction coil)"},
    {"y_mean_um", "um", &Metrics::y_mean_um, "y mean", 3, ""},
    {"window_start_s", "s", &Metrics::window_start_s, "", 0, ""},
    {"window_end_s", "s", &Metrics::window_end_s, "", 0, ""},
};

// Step response of a Step waveform (y over the run after the step time): 10-90 % rise time,
// overshoot beyond the final value, 2 % settling time. `valid` is false when the step moves
// y by less than 1e-9 um or the run records fewer than 3 samples after it.
struct StepMetrics {
  bool valid = false;
  double y_initial_um = 0, y_final_um = 0;  // y at the step; mean y over the last 10 % of the run
  double rise_time_s = 0;                   // 10 % -> 90 % of the change
  double overshoot_pct = 0;                 // largest excursion beyond y_final, % of the change
  double settling_time_s = 0;               // after the step, last leaving +-2 % of the change
};
StepMetrics step_metrics(const TimeSeries& ts, double step_time_s);

struct QuantityStats {
  std::string name;  // a column of the series, e.g. "rod1_F_N"
  double rms = 0, peak = 0, pp = 0, mean = 0;
};

// The coil as an amplifier sees it over the metrics window: v = i R + sum N dphi/dt (the
// terminal voltage with the coil's resistance at its temperature; thermal_network).
struct CoilElectrical {
  double resistance_ohm = 0;
  double current_rms_A = 0, voltage_rms_V = 0, voltage_peak_V = 0;
  double power_mean_W = 0;  // mean i v = copper + magnetic input
  double power_peak_W = 0;  // max |i v|
  double copper_W = 0;      // mean i^2 R
  double apparent_VA = 0;   // V_rms I_rms
};

struct Result {
  TimeSeries series;
  std::vector<QuantityStats> quantities;  // filled by add_quantity_stats()
  // Periodic runs: over the last whole period; other waveforms: over the whole run.
  Metrics metrics;
  bool has_metrics = false;
  StepMetrics step;  // Step waveforms
  double dt_s = 0;
  long steps = 0;
  double wall_time_s = 0;
  bool diverged = false;
  std::string error;  // DivergenceError message when diverged
  // The stack's thermal expansion x_T (eq. 21, relative to T_ref) at the end of the run, and
  // at its start: they differ when the actuator heats itself. The offset drift of the output
  // beside its stroke (whether or not y includes it: options.thermal_expansion_in_output).
  double thermal_expansion_um = 0;
  double thermal_expansion_start_um = 0;
  // The energy ledgers over the metrics window (SimulationSettings::energy_ledger).
  bool has_energy = false;
  EnergyBalance energy;
  CoilElectrical coil;
  // Self-heating: one row per thermal step (t_s, coil_C, rods_C, housing_C, P_copper_W,
  // P_eddy_W, P_hysteresis_W, P_damping_W (the rods' losses from the ledger), P_ambient_W,
  // stroke_um over the step, E_in_J, E_stored_J, E_out_J cumulative, xT_um (eq. 21 at the
  // step's end) and y_mean_um (the output's mean over it): the drift beside the stroke) and the
  // run's heat balance.
  TimeSeries heating;
  double energy_in_J = 0, energy_stored_J = 0, energy_out_J = 0;
};

// The validation layer (gmasim/model/validate.hpp): throws InputError naming the field, its value
// and the rule for a non-finite or out-of-range number (currents |I| <= kMaxCurrent_A,
// frequencies in (0, kMaxFrequency_Hz], a table that starts before t = 0 or later than 0,
// run lengths whose step count exceeds kMaxSteps or whose record exceeds kMaxRecordedRows).
// simulate() calls it first; callers that derive settings call it before any work.
inline constexpr double kMaxCurrent_A = 1000.0;
inline constexpr double kMaxFrequency_Hz = 1e6;
void validate(const Waveform& w);
void validate(const SimulationSettings& s);

// Runs the model. Never throws on divergence: the partial result is returned with
// diverged = true and error set. Throws InputError on bad settings.
Result simulate(const Model& m, const SimulationSettings& s);

// Metrics over [t0, t1] of a recorded run (uses columns t_s, current_A, y_um, B_T).
Metrics compute_metrics(const TimeSeries& ts, double t0_s, double t1_s);

// Stroke, hysteresis and B p-p of the samples [b, e) of one window (the row e, when given,
// closes a periodic window), from their cubic Hermite refinement (third order in the sample
// spacing, below the integrator's second order): the one loop measure of simulate(), the
// sweeps and identify's sine targets.
struct LoopMetrics {
  double stroke_um = 0, hysteresis_um = 0, B_pp_T = 0;
};
// Which of them to compute: a measure not wanted is left NaN and costs nothing (identify's sine
// targets need one or two of the three on most runs).
struct LoopMetricsWanted {
  bool stroke = true, hysteresis = true, B_pp = true;
};
LoopMetrics loop_metrics(const std::vector<double>& t_s, const std::vector<double>& current_A,
                         const std::vector<double>& y_um, const std::vector<double>& B_T,
                         std::size_t b, std::size_t e, LoopMetricsWanted want = {});

// max - min of v; 0 for an empty span. The one peak-to-peak of metrics, fits and records.
double peak_to_peak(std::span<const double> v);

// Largest gap between the rising-current and falling-current branches of y(I) at equal
// current, over one period of samples [um]. Both branches are interpolated onto a
// common grid of currents spanning their overlap.
double hysteresis_width(const std::vector<double>& current_A, const std::vector<double>& y,
                        std::size_t begin, std::size_t end);

struct RmsPeak {
  double rms = 0, peak = 0;  // RMS of the signal; peak of its absolute value
};
RmsPeak rms_and_peak(const std::vector<double>& v, std::size_t begin, std::size_t end);

// RMS, peak |v|, peak-to-peak and mean of each named column over the metrics window
// (the last whole period), or over the whole run when the run is not periodic.
// Throws InputError naming the recorded columns when a name is unknown.
void add_quantity_stats(Result& r, const std::vector<std::string>& names);

}  // namespace gmasim

namespace gmasim {

// The magnetic-state check of `gmasim model check` (issue 7): the model run over a standard
// grid (20/70/150 degC x 6/12 A peak-to-peak x 10/400 Hz, the biased sine of Fig. 11, two
// periods each). Reports the largest flux density the induction coil sees, the largest
// flux density phi/A the circuit assigns to a rod, and the largest departure of phi/A
// from the rod's own material state mu0 (H + M), with where each occurs.
struct MagneticStateCheck {
  double max_B_sensor_T = 0;                     // max |B| of the induction coil (State::B_T)
  double max_B_rod_T = 0;                        // max |phi_i / A_i| over rods and steps
  double max_inconsistency_T = 0;                // max |phi_i / A_i - mu0 (H_i + M_i)|
  double max_inconsistency_rel = 0;              // the same over mu0 (|H| + M_s^T) of that rod
  std::string where_B_rod, where_inconsistency;  // "rod2, 150 degC, 12 A, 10 Hz, t = ... s"
  // The energy ledgers (gmasim/model/energy.hpp) over the last period of each run: the worse
  // relative residual of the two, where, and the largest coupling fraction (the mechanical
  // input the one-way coupling does not draw from the coil, over the magnetic input).
  double energy_residual_rel = 0;
  std::string where_energy;
  double max_coupling_fraction = 0;
  int runs = 0;
  std::string divergence;  // the first run that diverged, if any (its samples still count)
};
MagneticStateCheck check_magnetic_state(const Model& m);

// The time-step table of docs/model.md ("Time step"), as markdown: stroke and hysteresis at
// 8 A, 70 degC, 10/100/400 Hz with the automatic dt and its halves, the observed order at
// 400 Hz (dt 20 / 10 / 5 / 2.5 us) and each rod's 2 mu0 kappa. `gmasim model check
// --dt-table` prints it. Throws DivergenceError.
std::string time_step_table_markdown(const Model& m);

}  // namespace gmasim
