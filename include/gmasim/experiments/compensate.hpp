// Temperature compensation (issue 9, item 2; docs/experiments.md, "Temperature
// compensation"): the drive that restores a target stroke at each temperature, the gain
// schedule it defines over a temperature range, and closed-loop tracking with that schedule
// as temperature feed-forward beside the plain PID.
#pragma once

#include <string>
#include <vector>

#include "gmasim/experiments/experiments.hpp"

namespace gmasim {

// What the compensation changes in the biased sine i(t) = min + pp/2 (1 - cos 2 pi f t):
//   Amplitude: pp, with the minimum held (the paper's -3 A), so the bias moves with pp;
//   Swing:     pp about a fixed mean current (min + pp/2 of the reference drive);
//   Scale:     min and pp together by a gain g (an amplifier gain: the waveform's shape kept).
enum class CompensationAdjust { Amplitude, Swing, Scale };
// The names of the adjust modes ("amplitude", "swing", "scale"), one table for the CLI, the
// Python module and the report. parse_compensation_adjust throws InputError naming them.
const char* compensation_adjust_name(CompensationAdjust a);
CompensationAdjust parse_compensation_adjust(const std::string& name);

// The tracking comparison compensate runs beside the schedule (run_compensated_track): the PID of
// `gmasim track` plain and with the schedule as temperature feed-forward. One struct for the
// CLI's options and Python's arguments, so their defaults are one (issue 41).
struct CompensateTracking {
  bool enabled = true;                          // CLI --no-track, Python track=False: off
  std::vector<double> temperatures_C;           // empty: the schedule's temperatures
  std::vector<double> amplitudes_um{10, 20};    // the references' amplitudes [um]
  std::vector<double> frequencies_Hz{10, 100};  // and frequencies [Hz]
  double bias_A = TrackRequest{}.bias_A;        // the loop's bias [A]
  double current_limit_A = TrackRequest{}.current_limit_A;  // the amplifier's +- limit [A]
};

struct CompensateRequest {
  // The target: target_stroke_um if > 0; else the stroke of the reference drive at the
  // reference temperature, lowered (when lower_target_to_reach) to the smallest of the
  // temperatures' reach -- the stroke of the largest drive max_current_A allows -- if it
  // exceeds that, so that every temperature of the schedule reaches the default target.
  double reference_temperature_C = 20.0;
  double reference_current_pp_A = 8.0;
  double current_min_A = -3.0;  // of the reference drive
  double target_stroke_um = 0.0;
  std::vector<double> temperatures_C{20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120, 130, 140, 150};
  double frequency_Hz = 10.0;
  double periods = 3.0;  // the stroke is the peak-to-peak of y over the last period
  CompensationAdjust adjust = CompensationAdjust::Amplitude;
  double max_current_A = 30.0;  // no drive may exceed |i| = max_current_A (the amplifier)
  double tolerance_um = 1e-3;   // |stroke - target| of a solved point
  double dt_s = 0.0;            // 0: the automatic rule
  int threads = 0;
  // The searches of the temperatures run in lock step, their runs advancing together in SIMD
  // lanes (gmasim/simulate/lanes.hpp) where the model allows; false: one simulate() per run.
  bool lanes = true;
  // false: a default target stays the reference's stroke even where no drive reaches it (the
  // temperature feed-forward's schedule, whose gains are relative to the reference drive).
  bool lower_target_to_reach = true;
  CompensateTracking tracking;
};

struct CompensatePoint {
  double temperature_C = 0;
  double current_pp_A = 0, current_min_A = 0, current_max_A = 0;  // the compensated drive
  double gain = 0;                     // pp / pp_ref (Amplitude, Swing) or g (Scale) [-]
  double stroke_um = 0;                // with the compensated drive
  double uncompensated_stroke_um = 0;  // with the reference drive at this temperature
  double reach_stroke_um = 0;          // with the largest drive max_current_A allows (the envelope)
  double hysteresis_um = 0, B_pp_T = 0;  // with the compensated drive
  int evaluations = 0;                   // simulations of the root search
  bool reachable = true;  // false: even max_current_A gives less than the target (the point
                          // then holds that largest drive and its stroke)
  bool diverged = false;
  std::string error;
};

struct CompensateResult {
  double target_stroke_um = 0;
  bool target_lowered = false;  // the reference's stroke was beyond some temperature's reach
  Metrics reference;            // the reference drive at the reference temperature
  std::vector<CompensatePoint> points;
  double wall_time_s = 0;
  int threads = 0;
};

// Throws InputError for a non-finite or out-of-range number, an empty list, a temperature
// at or above T_c, a reference drive beyond max_current_A, a target stroke the reference
// cannot define (0 um).
CompensateResult run_compensate(const Model& m, const CompensateRequest& r,
                                const ProgressFn& progress = {});

// The schedule's gain at temperature T: linear interpolation between the solved points,
// held constant beyond the ends. Throws InputError if there is no reachable point.
double schedule_gain(const CompensateResult& r, double temperature_C);

// Tracking with and without temperature feed-forward: the same TrackRequest run plain and
// with feedforward = the gain schedule of the loop's own operating point (a Swing
// compensation of a +-half A sine about the track bias, half = min(1 A, limit/2), at the
// compensation's frequency and the track temperatures) and that drive's static gain at the
// reference temperature. The error growth the feed-forward removes is read off the two.
struct CompensatedTrack {
  TrackResult plain, compensated;
  CompensateResult loop_schedule;   // the Swing schedule about the bias
  double static_gain_um_per_A = 0;  // stroke / pp of that drive at the reference temperature
};
// The temperature feed-forward of run_compensated_track (the Swing schedule about the track
// bias at the track temperatures, with its static gain); the schedule itself in *schedule if
// given. Throws InputError if no temperature reaches the target.
TemperatureFeedforward loop_temperature_feedforward(const Model& m, const CompensateRequest& creq,
                                                    const TrackRequest& treq,
                                                    CompensateResult* schedule = nullptr,
                                                    const ProgressFn& progress = {});
CompensatedTrack run_compensated_track(const Model& m, const CompensateRequest& creq,
                                       TrackRequest treq, const ProgressFn& progress = {});
// The tracking of creq.tracking (TrackRequest's defaults otherwise; its temperatures the
// schedule's when none are given), its numbers checked under compensate's own flag names
// (--track-amplitudes, --track-frequencies, --bias, --current-limit); then the comparison.
TrackRequest compensate_track_request(const CompensateRequest& creq);
CompensatedTrack run_compensated_track(const Model& m, const CompensateRequest& creq,
                                       const ProgressFn& progress = {});

// The coil's copper loss under a biased sine of p-p i_pp_A from i_min_A with the coil at T_C
// [W]: I_rms^2 R(T), I_rms^2 = mean^2 + (i_pp/2)^2 / 2, R(T) = R (1 + alpha (T - T_ref)) of
// [thermal_network] (the schedule's column copper_loss_W).
double coil_copper_loss_W(const Model& m, double i_min_A, double i_pp_A, double T_C);

// What a schedule costs the coil: its largest copper loss, where, and the steady rise of the
// housing above ambient that loss gives over thermal_network.housing_to_ambient_W_per_K [K].
struct ScheduleHeating {
  double max_copper_loss_W = 0, at_temperature_C = 0, steady_rise_K = 0;
};
ScheduleHeating schedule_heating(const Model& m, const CompensateResult& res);

Report compensate_report(const Model& m, const CompensateRequest& req, const CompensateResult& res,
                         const CompensatedTrack* track = nullptr);

}  // namespace gmasim
