// Inverse-model feed-forward tracking (issue 20; docs/experiments.md, "Inverse-model
// feed-forward"). Ahead of the PID, the current the model at the loop's temperature says
// produces the reference:
//
//   1. a stable inverse of the model's linear part: the small-signal response about the bias
//      (linearise(), eddy lag of eq. 7 and the mechanics of eq. 15), normalised to its static
//      gain, H(s) = Y(s) / Y(0), is inverted as a polynomial in s fitted by least squares over
//      (0, band]:  1 / H(j w) ~ 1 + a1 (j w) + a2 (j w)^2 + a3 (j w)^3.  Applied to the preview
//      of a known reference (its derivatives at t_k + T_s/2, half a sample ahead for the
//      zero-order hold) it is a finite filter: stable whatever H's zeros, no sample-by-sample
//      inversion of the dynamic step (whose inverse is unstable);
//   2. a quasi-static inverse of the model with its hysteresis and temperature: a shadow state
//      of the model follows its quasi-static loop (quasi_static_step: eq. 9 without eddy lag,
//      static mechanics) under the feed-forward current; at each sample a safeguarded secant
//      (Newton with a numerical slope, bisection inside the bracket when a step leaves it)
//      finds the current whose quasi-static output is the filtered target, on the branch the
//      shadow is on. The current is clipped to the drive's limits +-current_limit_A.
//
// Allocation-free per sample (tests/test_feedforward.cpp counts).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/model/model.hpp"

namespace gmasim {

// The polynomial inverse of H(s) = Y(s) / Y(0) about the bias (step 1 above).
struct LinearInverse {
  std::array<double, 3> a{};        // a1 [s], a2 [s^2], a3 [s^3]
  double band_Hz = 0;               // the fit band (0, band]
  double max_residual = 0;          // max |P(j w) H(j w) - 1| over the fit grid [-]
  double static_gain_um_per_A = 0;  // |Y(0) / I| of the linearisation
};

// Settles the model at the bias (settle_at_bias, anhysteretic), linearises it and fits the
// inverse over 48 log-spaced frequencies in [band/100, band]. Throws InputError for a band
// outside (0, 1e5] Hz, DivergenceError if the bias point does not settle.
LinearInverse fit_linear_inverse(const Model& m, const Conditions& c, double bias_A,
                                 double band_Hz);

struct InverseFeedforwardSettings {
  double bias_A = 1.0;            // the shadow starts at rest under it (make_state)
  double current_limit_A = 10.0;  // the drive: the feed-forward current stays within +-this
  double sample_rate_Hz = 1e4;    // the preview is half a sample
  double band_Hz = 500.0;         // fit band of the linear inverse
  bool dynamic = true;            // false: the quasi-static inverse alone (P = 1)
  double tolerance_um = 1e-4;     // |y_qs(I) - target| of the quasi-static solve
};

class InverseFeedforward {
 public:
  // The model at the loop's temperature. Fits the linear inverse (fit_linear_inverse) unless
  // `linear` is given (a fit of the same model, temperature, bias and band).
  InverseFeedforward(const Model& m, double temperature_C, const InverseFeedforwardSettings& s,
                     const LinearInverse* linear = nullptr);
  // Back to rest under the bias (the shadow's hysteresis history forgotten).
  void reset();
  // The output at rest under the bias [um]: the reference's bias point in the model.
  double y_bias_um() const { return y_bias_m_ * 1e6; }
  // The feed-forward current for one sample [A], within +-current_limit_A. r[0] is the
  // reference's deviation from its bias point [um], r[1..3] its first three time derivatives
  // [um/s^n], all at the sample time plus half a sample (the caller's preview). Advances the
  // shadow state to the returned current. Allocation-free.
  double current_A(const std::array<double, 4>& r);
  // The quasi-static target of the last sample, y_bias + P(d/dt) r [um].
  double last_target_um() const { return target_m_ * 1e6; }
  int last_evaluations() const { return evaluations_; }  // quasi-static steps of the last solve
  const LinearInverse& linear() const { return lin_; }
  const InverseFeedforwardSettings& settings() const { return set_; }

 private:
  double output_at(double current_A);  // the trial: shadow + quasi_static_step -> y [m]
  double solve(double target_m);

  const Model* m_;
  Conditions c_;
  InverseFeedforwardSettings set_;
  LinearInverse lin_;
  State shadow_, trial_;
  double y_bias_m_ = 0, target_m_ = 0, slope_m_per_A_ = 0, trial_current_A_ = 0;
  int evaluations_ = 0;
};

// ---------------------------------------------------------------------------------------
// Evaluation against plants that differ from the feed-forward's model (issue 20).
// ---------------------------------------------------------------------------------------

enum class TrackController { Pid, PidTemperature, PidInverse };
// "pid", "pid_temperature", "pid_inverse"; parse_track_controller throws InputError naming them.
const char* track_controller_name(TrackController c);
TrackController parse_track_controller(const std::string& name);
// Their names, in order (the CLI's and Python's default: FeedforwardEvaluationRequest{}'s).
std::vector<std::string> track_controller_names(const std::vector<TrackController>& cs);

// A plant that differs from the model: M_s (material.Ms_A_per_m), the JA pinning k of every
// rod (rodN.ja.k0_A_per_m) and lambda_s (material.lambda_s) scaled, and the plant at the loop's
// temperature plus an offset.
struct PlantMismatch {
  std::string label;  // "Ms+ k- ls+ T+10" (signs of the factors, the offset in degC), "none"
  double Ms_factor = 1, k_factor = 1, lambda_s_factor = 1, temperature_offset_C = 0;
};
// The 16 combinations: (1 +- fraction) on M_s, k, lambda_s (8 sign combinations) times the
// temperature offset +-offset_C; in the order T+ then T-, each M_s, k, lambda_s as binary
// digits (+ before -).
std::vector<PlantMismatch> plant_mismatches(double fraction = 0.10, double offset_C = 10.0);
PlantMismatch perfect_plant();  // "none": the plant is the model
// "all": plant_mismatches(); "none": {perfect_plant()}; "both": the perfect plant, then the 16.
// Throws InputError naming the words for any other.
std::vector<PlantMismatch> parse_plant_mismatches(const std::string& word);
// The model with the mismatch's factors (ModelSpec::set, then compile). Throws InputError if a
// scaled value breaks a rule of the parameter table.
Model mismatched_plant(const Model& m, const PlantMismatch& mismatch);

struct FeedforwardEvaluationRequest {
  TrackRequest track;  // the grid (temperatures, amplitudes, frequencies), gains and drive;
                       // its feed-forward fields are set per controller
  std::vector<PlantMismatch> mismatches = plant_mismatches();
  std::vector<TrackController> controllers{TrackController::Pid, TrackController::PidTemperature,
                                           TrackController::PidInverse};
  double schedule_frequency_Hz = 10.0;  // of the temperature schedule (pid_temperature)
};

struct FeedforwardRun {
  std::string mismatch;
  TrackController controller = TrackController::Pid;
  double plant_temperature_C = 0;
  TrackPoint point;  // temperature_C: the loop's (the feed-forward model's)
};

// RMS(pid) / RMS(controller) over the mismatches of one grid point.
struct FeedforwardRatio {
  double temperature_C = 0, frequency_Hz = 0, amplitude_um = 0;
  TrackController controller = TrackController::PidInverse;
  int combinations = 0;  // mismatches with both runs finite
  double median = 0, min = 0, max = 0;
};

struct FeedforwardEvaluation {
  std::vector<FeedforwardRun> runs;  // order: temperature, amplitude, frequency, mismatch,
                                     // controller
  std::vector<FeedforwardRatio> ratios;
  std::vector<LinearInverse> inverses;             // per temperature of the request
  TemperatureFeedforward temperature_feedforward;  // the pid_temperature schedule
  double wall_time_s = 0;
  int threads = 0;
};

// Every run of the grid; the temperature schedule of pid_temperature is computed on the model
// (gmasim/experiments/compensate.hpp, loop_temperature_feedforward). Plant steps per frequency.
FeedforwardEvaluation run_feedforward_evaluation(const Model& m,
                                                 const FeedforwardEvaluationRequest& r,
                                                 const ProgressFn& progress = {});

// Tables "runs" (track.csv), "ratios" (track_ratios.csv), "inverse" (track_inverse.csv).
Report feedforward_report(const Model& m, const FeedforwardEvaluationRequest& req,
                          const FeedforwardEvaluation& res);

}  // namespace gmasim
