// The paper's experiments (sections 4.4, 4.5, 5) as library functions returning result
// structs. The CLI, the Python module and `gmasim reproduce` are thin shells over these.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "gmasim/model.hpp"
#include "gmasim/simulate.hpp"

namespace gmasim {

// Progress callback: (points done, points total). Called from worker threads, serialised.
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

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
  double dt_s = 0.0;                      // 0: auto_dt
  int threads = 0;                        // 0: all hardware threads
  Freeze freeze;
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
  double wall_time_s = 0;
  int threads = 0;
};

// Throws InputError for an empty grid, a frequency <= 0, a temperature at/above T_c.
// Deterministic whatever the thread count.
SweepResult run_sweep(const Model& m, const SweepRequest& r, const ProgressFn& progress = {});

// ---------------------------------------------------------------------------------------
// Frequency response current -> displacement (Fig. 15) and the modes of eq. (15).
// ---------------------------------------------------------------------------------------
struct FrfRequest {
  std::vector<double> temperatures_C{20, 70};
  double f_min_Hz = 1.0, f_max_Hz = 5000.0;
  int points = 40;              // log-spaced
  double bias_A = 1.0;          // DC bias current (the middle of the 8 A sine of Fig. 11)
  double amplitude_A = 0.05;    // stepped-sine amplitude (small signal)
  int settle_periods = 4, measure_periods = 2;
  bool stepped_sine = true, small_signal = true;
};

struct FrfCurve {
  double temperature_C = 0;
  std::vector<double> f_Hz;
  // Stepped sine (time-domain simulation, first harmonic of y over the current) [um/A, deg]
  std::vector<double> stepped_mag_um_per_A, stepped_phase_deg;
  // Small-signal linearisation about the bias point [um/A, deg]
  std::vector<double> linear_mag_um_per_A, linear_phase_deg;
  double first_resonance_Hz = 0;   // largest peak of |Y/I| (linear model) in the band, 0 if none
  double bandwidth_3dB_Hz = 0;     // first f where |Y/I| falls 3 dB below its low-f value
  std::vector<double> mode_frequencies_Hz;  // eq. (15) eigen-analysis at the bias point
  std::vector<double> mode_damping_ratios;
};

struct FrfResult {
  std::vector<FrfCurve> curves;
  double paper_first_resonance_Hz = 1270.0;  // Fig. 15, for the report
};

FrfResult run_frf(const Model& m, const FrfRequest& r, const ProgressFn& progress = {});

// ---------------------------------------------------------------------------------------
// Closed-loop tracking with the paper's PID (Fig. 16).
// ---------------------------------------------------------------------------------------
struct PidGains {
  double kp = 0.2, ki = 0.03, kd = 0.007;  // units: docs/experiments.md
};

struct TrackRequest {
  std::vector<double> temperatures_C{20, 30, 40, 50, 60, 70};
  std::vector<double> amplitudes_um{10, 20};
  std::vector<double> frequencies_Hz{10, 100};
  PidGains gains;
  double sample_rate_Hz = 10000.0;   // controller and sensor sample rate
  double bias_A = 1.0;               // coil bias the controller output is added to
  double current_limit_A = 10.0;     // amplifier saturation (+-)
  double sensor_noise_um = 0.0;      // RMS white noise of the displacement sensor
  double periods = 4.0;              // errors over the last period
  int threads = 0;
};

struct TrackPoint {
  double temperature_C = 0, amplitude_um = 0, frequency_Hz = 0;
  double error_rms_um = 0, error_peak_um = 0;
  double error_change_pct = 0;  // vs the first temperature of the request
  bool diverged = false;
  std::string error;
};

struct TrackResult {
  std::vector<TrackPoint> points;
  TimeSeries example;  // one run (first point): t_s, reference_um, y_um, current_A, error_um
};

// Throws InputError if the sample rate is below twice a reference frequency.
TrackResult run_track(const Model& m, const TrackRequest& r, const ProgressFn& progress = {});

// ---------------------------------------------------------------------------------------
// Ablation (Fig. 20): freeze one temperature law at 20 degC, one at a time.
// ---------------------------------------------------------------------------------------
struct AblateRequest {
  double temperature_C = 70.0;
  std::vector<double> frequencies_Hz{10, 200};
  double current_pp_A = 6.0;
  double periods = 3.0;
};

struct AblationRow {
  std::string law;          // "mu_G", "rho_G", "M", "E_G", "E_t" (and "F_pm", "geometry")
  double frequency_Hz = 0;
  double error_rms_um = 0;  // RMS of y_frozen - y_full over the last period
  double error_pct_of_stroke = 0;
  double stroke_um = 0, hysteresis_um = 0;
};

struct AblateResult {
  std::vector<AblationRow> rows;
  std::vector<Metrics> full;  // the full model, one per frequency
};

AblateResult run_ablate(const Model& m, const AblateRequest& r);

// ---------------------------------------------------------------------------------------
// Parameters against temperature (Fig. 19) and stroke retention (Fig. 18).
// ---------------------------------------------------------------------------------------
struct ParamsVsTemperatureRequest {
  std::vector<double> temperatures_C{20, 40, 60, 80, 100, 120, 150};
  double current_pp_A = 8.0, frequency_Hz = 10.0;  // the operating point of Fig. 19
  std::vector<double> retention_currents_pp_A{6, 8, 10, 12};
};

struct ParamsVsTemperatureRow {
  double temperature_C = 0;
  std::string rod;
  double mu_r_mean = 0;      // mu_G / mu0, mean over the last period
  double rho_ohm_m = 0;      // eq. (8)
  double M_peak_A_per_m = 0; // peak magnetisation over the last period
  double MsT_A_per_m = 0;    // eq. (4)
  double E_G_mean_GPa = 0;   // eq. (13), mean over the last period
  double E_t_GPa = 0;        // eq. (19)
};

struct RetentionRow {
  double current_pp_A = 0, temperature_C = 0, stroke_um = 0, hysteresis_um = 0;
  double stroke_retention_pct = 0;  // vs the first temperature
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
  double paper_model_um_per_C = 0.662, paper_measured_um_per_C = 0.712;
};

ThermalExpansionResult thermal_expansion_coefficient(const Model& m);

}  // namespace gmasim
