// The request tables of the experiments of gmasim/experiments.hpp (issue 21, item 3): one row
// per field (gmasim/experiments/request_table.hpp). The order of the rows is the order of the
// report's metadata and of the Python keyword arguments; the defaults are the structs'
// initialisers.
#pragma once

#include <tuple>

#include "gmasim/experiments/compensate.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/feedforward.hpp"
#include "gmasim/experiments/request_table.hpp"
#include "gmasim/experiments/sensitivity.hpp"
#include "gmasim/experiments/shared_rows.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim::fields {

inline constexpr unsigned kCliPy = Cli | Python;
inline constexpr unsigned kCliMeta = Cli | Meta;
inline constexpr Rule kCurrent = in(-kMaxCurrent_A, kMaxCurrent_A);

// Rows that several requests share, spelled once.
// threads: resolve_thread_count() checks it (0 or 1..kMaxThreads) with its own message.
template <class R>
constexpr auto threads_row(unsigned where) {
  return field<R>("threads", "-", any(), "--threads", "Worker threads [-]; 0 = all cores", where,
                  GMASIM_REF(R, threads));
}
template <class R>
constexpr auto temperatures_row(std::string_view help = "Temperatures [degC]; list or range") {
  return field<R>("temperatures_C", "degC", finite(), "--temperatures", help, kCliPy,
                  GMASIM_REF(R, temperatures_C));
}
template <class R>
constexpr auto current_min_row(std::string_view help = "Minimum of the biased sine [A]") {
  return field<R>("current_min_A", "A", finite(), "--current-min", help, kCliMeta,
                  GMASIM_REF(R, current_min_A));
}

template <>
struct RequestFields<SweepRequest> {
  using R = SweepRequest;
  static constexpr std::string_view experiment = "sweep";
  static constexpr auto rows = std::tuple{
      temperatures_row<R>("Temperatures [degC]: list '20,30,40' or range start:step:stop"),
      field<R>("currents_pp_A", "A", nonnegative(), "--currents",
               "Current peak-to-peak values [A] of the biased sine (Fig. 11); list or range",
               kCliPy, GMASIM_REF(R, currents_pp_A)),
      field<R>("frequencies_Hz", "Hz", positive(), "--frequencies",
               "Excitation frequencies [Hz]; list or range", kCliPy, GMASIM_REF(R, frequencies_Hz)),
      field<R>("reference_temperature_C", "degC", finite(), "--reference-temperature",
               "Relative changes are against this temperature [degC] (run even if not in the "
               "grid)",
               All, GMASIM_REF(R, reference_temperature_C)),
      current_min_row<R>("Minimum of the biased sine [A] (paper: -3 A)"),
      periods_row<R>("Periods per point [-]; metrics over the last one", All),
      dt_row<R>("Time step [s]; 0 = automatic rule (T/2000, at most 10 us)", All),
      threads_row<R>(kCliPy),
  };
};

template <>
struct RequestFields<FrfRequest> {
  using R = FrfRequest;
  static constexpr std::string_view experiment = "frf";
  static constexpr auto rows = std::tuple{
      temperatures_row<R>(),
      field<R>("f_min_Hz", "Hz", positive(), "--f-min", "Lowest frequency [Hz]", kCliPy,
               GMASIM_REF(R, f_min_Hz)),
      field<R>("f_max_Hz", "Hz", in(0.0, kMaxFrequency_Hz), "--f-max", "Highest frequency [Hz]",
               kCliPy, GMASIM_REF(R, f_max_Hz)),
      field<R>("points", "-", in(2, kMaxFrfPoints), "--points", "Log-spaced frequencies [-]",
               kCliPy, GMASIM_REF(R, points)),
      field<R>("bias_A", "A", kCurrent, "--bias",
               "DC bias current [A] (1 A: middle of the 8 A sine)", All, GMASIM_REF(R, bias_A)),
      field<R>("amplitude_A", "A", in(0.0, kMaxCurrent_A), "--amplitude",
               "Stepped-sine current amplitude [A]; above the small-signal limit (printed per "
               "temperature, about 2 mA for the built-in model) the FRF is large-signal "
               "(docs/experiments.md)",
               All, GMASIM_REF(R, amplitude_A)),
      field<R>("peak_refinements", "-", in(0, 100), "--peak-refinements",
               "Stepped sine: golden-section evaluations refining the largest |Y/I| peak (and one "
               "point at the linearisation's peak) [-]; 0 = off, at most 100",
               All, GMASIM_REF(R, peak_refinements)),
      // --bias-state and --method (both bools) are the CLI's own options (apps/gmasim/cmd_frf.cpp).
      field<R>("bias_state", "-", any(), "", "", Meta, GMASIM_REF(R, bias_state)),
      field<R>("stepped_sine", "-", any(), "", "", Python | Meta, GMASIM_REF(R, stepped_sine)),
      field<R>("small_signal", "-", any(), "", "", Python | Meta, GMASIM_REF(R, small_signal)),
      field<R>("settle_periods", "-", in(1, 1e6), "--settle-periods",
               "Stepped sine: minimum settling periods [-] (also >= 10 time constants)", kCliMeta,
               GMASIM_REF(R, settle_periods), "settle_periods_min"),
      field<R>("measure_periods", "-", in(1, 1e6), "--measure-periods",
               "Stepped sine: periods in the first-harmonic measurement [-]", kCliMeta,
               GMASIM_REF(R, measure_periods)),
      threads_row<R>(kCliPy),
  };
};

template <>
struct RequestFields<TrackRequest> {
  using R = TrackRequest;
  static constexpr std::string_view experiment = "track";
  static constexpr auto rows = std::tuple{
      temperatures_row<R>(),
      field<R>("amplitudes_um", "um", in(0.0, kMaxTrackAmplitude_um), "--amplitudes",
               "Reference amplitudes [um] (sine about y_bias)", kCliPy,
               GMASIM_REF(R, amplitudes_um)),
      field<R>("frequencies_Hz", "Hz", in(0.0, kMaxFrequency_Hz), "--frequencies",
               "Reference frequencies [Hz]", kCliPy, GMASIM_REF(R, frequencies_Hz)),
      field<R>("kp", "A/um", finite(), "--kp", "Proportional gain [unit/um]", All,
               GMASIM_REF(R, gains.kp), "kp_A_per_um"),
      field<R>("ki", "A/um per sample", finite(), "--ki",
               "Integral gain [A/um per sample at --gain-rate]: u += ki * sum(e)", All,
               GMASIM_REF(R, gains.ki), "ki_A_per_um_per_sample_at_reference_rate"),
      field<R>("kd", "A/um per sample", finite(), "--kd",
               "Derivative gain [A/um per sample at --gain-rate]: u += kd * (e_k - e_k-1)", All,
               GMASIM_REF(R, gains.kd), "kd_A_per_um_per_sample_at_reference_rate"),
      field<R>("gain_rate_Hz", "Hz", in(1e-3, 1e9), "--gain-rate",
               "Sample rate [Hz] at which ki and kd are per-sample gains; other sample rates "
               "rescale them so the continuous controller is unchanged",
               kCliMeta, GMASIM_REF(R, gains.reference_rate_Hz), "gains_reference_rate_Hz"),
      field<R>("sample_rate_Hz", "Hz", in(0.0, 1e3 * kMaxFrequency_Hz), "--sample-rate",
               "Controller and sensor sample rate [Hz]; must be >= 2x every reference frequency",
               All, GMASIM_REF(R, sample_rate_Hz)),
      field<R>("bias_A", "A", kCurrent, "--bias",
               "Coil bias current the PID output is added to [A]", All, GMASIM_REF(R, bias_A)),
      field<R>("current_limit_A", "A", in(0.0, kMaxCurrent_A), "--current-limit",
               "Amplifier saturation: coil current clipped to +- this [A]", kCliMeta,
               GMASIM_REF(R, current_limit_A)),
      field<R>("amplifier_A_per_unit", "A/unit", in(1e-6, 1e6), "--amplifier-gain",
               "Coil current per unit of PID output [A/unit] (the amplifier; the paper does not "
               "print it: docs/experiments.md)",
               All, GMASIM_REF(R, amplifier_A_per_unit)),
      field<R>("sensor_noise_um", "um", in(0.0, kMaxTrackAmplitude_um), "--sensor-noise",
               "White noise of the displacement sensor [um RMS]", All,
               GMASIM_REF(R, sensor_noise_um), "sensor_noise_um_rms"),
      field<R>("noise_seed", "-", any(), "--seed", "Seed of the sensor-noise generator [-]",
               kCliMeta, GMASIM_REF(R, noise_seed)),
      periods_row<R>("Reference periods per run [-]; errors over the last", All),
      dt_row<R>("Plant time step [s]; 0 = automatic (<= 10 us, <= T/2000, divides 1/fs)", kCliPy),
      threads_row<R>(kCliPy),
      field<R>("feedforward_band_Hz", "Hz", in(0.0, 1e5), "--feedforward-band",
               "Fit band of the linear part's inverse [Hz]", kCliPy,
               GMASIM_REF(R, inverse.band_Hz)),
  };
};

template <>
struct RequestFields<AblateRequest> {
  using R = AblateRequest;
  static constexpr std::string_view experiment = "ablate";
  static constexpr auto rows = std::tuple{
      field<R>("temperature_C", "degC", finite(), "--temperature", "Operating temperature [degC]",
               All, GMASIM_REF(R, temperature_C)),
      field<R>("frequencies_Hz", "Hz", positive(), "--frequencies",
               "Excitation frequencies [Hz]; list or range", kCliPy, GMASIM_REF(R, frequencies_Hz)),
      field<R>("current_pp_A", "A", positive(), "--current-pp", "Current peak-to-peak [A]", All,
               GMASIM_REF(R, current_pp_A)),
      current_min_row<R>(),
      periods_row<R>("Periods per run [-]; errors over the last", kCliMeta),
      threads_row<R>(Cli),
  };
};

template <>
struct RequestFields<ParamsVsTemperatureRequest> {
  using R = ParamsVsTemperatureRequest;
  static constexpr std::string_view experiment = "params-vs-temperature";
  static constexpr auto rows = std::tuple{
      temperatures_row<R>(),
      field<R>("current_pp_A", "A", positive(), "--current-pp",
               "Current peak-to-peak of the Fig. 19 operating point [A]", All,
               GMASIM_REF(R, current_pp_A)),
      field<R>("frequency_Hz", "Hz", positive(), "--frequency", "Excitation frequency [Hz]", All,
               GMASIM_REF(R, frequency_Hz)),
      field<R>("retention_currents_pp_A", "A", positive(), "--retention-currents",
               "Current peak-to-peak values of the retention table [A]; list or range", Cli,
               GMASIM_REF(R, retention_currents_pp_A)),
      current_min_row<R>(),
      periods_row<R>("Periods per run [-]; statistics over the last", kCliMeta),
      dt_row<R>("Time step [s]; 0 = automatic rule (T/2000, at most 10 us; gmasim reproduce "
                "gives the claims' 25 us at 10 Hz)",
                All),
      threads_row<R>(Cli),
  };
};

// --adjust is the CLI's own option (a choice) and an extra argument of Python's compensate();
// the report records it first. The target stroke it records is the result's (the solved one).
template <>
struct RequestFields<CompensateRequest> {
  using R = CompensateRequest;
  static constexpr std::string_view experiment = "compensate";
  static constexpr auto rows = std::tuple{
      field<R>("adjust", "-", any(), "", "", Meta, GMASIM_REF(R, adjust)),
      temperatures_row<R>("Temperatures of the schedule [degC]: list or start:step:stop"),
      field<R>("reference_temperature_C", "degC", finite(), "--reference-temperature",
               "Temperature whose stroke is the target [degC]", All,
               GMASIM_REF(R, reference_temperature_C)),
      field<R>("reference_current_pp_A", "A", in(0.0, 2.0 * kMaxCurrent_A),
               "--reference-current-pp", "Reference drive: biased-sine current peak-to-peak [A]",
               All, GMASIM_REF(R, reference_current_pp_A)),
      field<R>("current_min_A", "A", kCurrent, "--current-min",
               "Reference drive: current minimum [A]", All, GMASIM_REF(R, current_min_A),
               "reference_current_min_A"),
      field<R>("target_stroke_um", "um", in(0.0, kMaxTrackAmplitude_um), "--target-stroke",
               "Target stroke [um]; 0 = the reference drive's stroke at the reference temperature",
               kCliPy, GMASIM_REF(R, target_stroke_um)),
      field<R>("frequency_Hz", "Hz", in(0.0, kMaxFrequency_Hz), "--frequency",
               "Drive frequency [Hz]", All, GMASIM_REF(R, frequency_Hz)),
      periods_row<R>("Periods per run; the stroke is over the last [-]", Cli),
      field<R>("max_current_A", "A", in(0.0, kMaxCurrent_A), "--max-current",
               "Largest |current| any drive may reach [A]", All, GMASIM_REF(R, max_current_A)),
      field<R>("tolerance_um", "um", in(1e-9, 1e3), "--tolerance",
               "Stroke tolerance of the solved drive [um]", All, GMASIM_REF(R, tolerance_um)),
      dt_row<R>("Time step [s]; 0 = automatic rule", Cli),
      threads_row<R>(kCliPy),
      // The tracking comparison (CompensateTracking): the CLI's and Python's one set of defaults.
      field<R>("track_temperatures_C", "degC", finite(), "--track-temperatures",
               "Tracking temperatures [degC]; default: the schedule's", kCliPy,
               GMASIM_REF(R, tracking.temperatures_C)),
      field<R>("track_amplitudes_um", "um", in(0.0, kMaxTrackAmplitude_um), "--track-amplitudes",
               "Tracking amplitudes [um]", kCliPy, GMASIM_REF(R, tracking.amplitudes_um)),
      field<R>("track_frequencies_Hz", "Hz", in(0.0, kMaxFrequency_Hz), "--track-frequencies",
               "Tracking frequencies [Hz]", kCliPy, GMASIM_REF(R, tracking.frequencies_Hz)),
      field<R>("bias_A", "A", kCurrent, "--bias", "Tracking: coil bias current [A]", kCliPy,
               GMASIM_REF(R, tracking.bias_A)),
      field<R>("current_limit_A", "A", in(0.0, kMaxCurrent_A), "--current-limit",
               "Tracking: amplifier limit +- [A]", kCliPy, GMASIM_REF(R, tracking.current_limit_A)),
  };
};

// The feed-forward evaluation (track --feedforward inverse): its grid, gains and drive are the
// track request's (the CLI's and Python's options are the track table's); the report records
// these of its rows. The plants and controllers are track's own options (words).
template <>
struct RequestFields<FeedforwardEvaluationRequest> {
  using R = FeedforwardEvaluationRequest;
  using T = TrackRequest;
  static constexpr std::string_view experiment = "track --feedforward";
  static constexpr auto rows = std::tuple{
      GMASIM_NESTED(R, track, T, "kp", Meta),
      GMASIM_NESTED(R, track, T, "ki", Meta),
      GMASIM_NESTED(R, track, T, "kd", Meta),
      GMASIM_NESTED(R, track, T, "sample_rate_Hz", Meta),
      GMASIM_NESTED(R, track, T, "bias_A", Meta),
      GMASIM_NESTED(R, track, T, "current_limit_A", Meta),
      GMASIM_NESTED(R, track, T, "amplifier_A_per_unit", Meta),
      GMASIM_NESTED(R, track, T, "periods", Meta),
      GMASIM_NESTED(R, track, T, "feedforward_band_Hz", Meta, "inverse_band_Hz"),
      field<R>("inverse_dynamic", "-", any(), "", "", Meta, GMASIM_REF(R, track.inverse.dynamic)),
      field<R>("schedule_frequency_Hz", "Hz", in(0.0, kMaxFrequency_Hz), "", "", Meta,
               GMASIM_REF(R, schedule_frequency_Hz)),
  };
};

// The sensitivity's settings (the rest of SensitivityRequest, parameters and quantities, are the
// command's own options and Python's own arguments). The CLI keeps its own checks and messages
// (apps/gmasim/cmd_sensitivity.cpp), run_sensitivity its own; the rules here are no stricter.
// The Meta rows are sensitivity.json's settings; a dotted key is a member of an inline object.
template <>
struct RequestFields<SensitivitySettings> {
  using R = SensitivitySettings;
  static constexpr std::string_view experiment = "sensitivity";
  static constexpr auto rows = std::tuple{
      field<R>("step_large", "-", in(0.0, 0.5), "--step-large", "The larger relative step h [-]",
               All, GMASIM_REF(R, step_large), "steps.large"),
      field<R>("step_small", "-", in(0.0, 0.5), "--step-small", "The smaller relative step h [-]",
               All, GMASIM_REF(R, step_small), "steps.small"),
      field<R>("agreement", "-", in(0.0, 1.0), "--agreement",
               "Flag an entry whose two estimates differ by more than this fraction [-]", All,
               GMASIM_REF(R, agreement)),
      field<R>("floor_fraction", "-", in(0.0, 1.0), "--floor",
               "Derivatives below this fraction of the quantity's tolerance count as zero [-]", All,
               GMASIM_REF(R, floor_fraction)),
      field<R>("near_null_ratio", "-", in(0.0, 1.0), "--near-null",
               "A singular direction below this fraction of the largest is near-null [-]", kCliPy,
               GMASIM_REF(R, near_null_ratio)),
      field<R>("quick", "-", any(), "--quick",
               "Score the claims on the quick study's grids (reproduce --quick)", All,
               GMASIM_REF(R, quick)),
      field<R>("use_claims", "-", any(), "", "", Python, GMASIM_REF(R, use_claims)),
      threads_row<R>(kCliPy),
  };
};

}  // namespace gmasim::fields
