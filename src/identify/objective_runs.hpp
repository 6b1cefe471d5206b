// The simulations of the identification objective besides its records (record_run.hpp): the
// shared start states, the biased-sine runs of the scalar targets and the resonance targets.
#pragma once

#include <deque>
#include <utility>
#include <vector>

#include "gmasim/identify/identify.hpp"
#include "gmasim/simulate/run_loop.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim::identify_detail {

// Conditions and the state at rest per (temperature, initial current): runs that share both
// (every frequency and amplitude of a biased sine starting at its -3 A minimum) share one
// make_state(), whose quasi-static ramp costs about as much as 300 steps.
class StartCache {
 public:
  explicit StartCache(const Model& m) : m_(m) {}
  const std::pair<Conditions, State>& get(double T, double I0);
  // Makes the states of the (temperature, initial current) pairs not cached yet and the extra
  // ramps (make_state of the model under extra_c[k] at extra_I0[k]) together, in SIMD lanes
  // (make_states, gmasim/simulate/lanes.hpp; the model lanes_supported): equal to make_state to
  // the lanes' rounding (~1e-14 relative), one ramp for all of them. Returns the extra states.
  // Fewer than two ramps in all: make_state (the pairs are then left to get()).
  std::vector<State> make_in_lanes(const std::vector<std::pair<double, double>>& T_I0,
                                   const std::vector<const Conditions*>& extra_c,
                                   const std::vector<double>& extra_I0);
  // make_in_lanes for several caches (of models of one structure) at once: every cache's ramps
  // in one make_states batch, each cache's entries and extra states those its own make_in_lanes
  // makes (the lanes read no other lane). extra_c[p], extra_I0[p]: cache p's extra ramps.
  static std::vector<std::vector<State>> make_in_lanes(
      const std::vector<StartCache*>& caches, const std::vector<std::pair<double, double>>& T_I0,
      const std::vector<std::vector<const Conditions*>>& extra_c,
      const std::vector<std::vector<double>>& extra_I0);

 private:
  struct Entry {
    double T, I0;
    std::pair<Conditions, State> cs;
  };
  // The (temperature, initial current) pairs not cached yet, each once.
  std::vector<std::pair<double, double>> missing(
      const std::vector<std::pair<double, double>>& T_I0) const;
  const Model& m_;
  std::deque<Entry> entries_;
};

// The biased sine of a stroke, hysteresis or B_pp target at one temperature, and the loop
// measures its targets read (the others are not computed: loop_metrics's want).
struct SineRun {
  double T, pp, f, min;
  LoopMetricsWanted want{false, false, false};
  // The drive current at the grid's times t0 + q dt, q = 0 .. steps (sine_drive): the same for
  // every candidate, so the objective computes it once; empty: run_sines_lanes computes it.
  std::vector<double> drive_A{};
  bool same_drive(const SineRun& o) const {
    return T == o.T && pp == o.pp && f == o.f && min == o.min;
  }
};

struct SineMetrics {
  double stroke_um = 0, hysteresis_um = 0, B_pp_T = 0;
};

// A sine run's grid: the claims' step (claim_dt, as gmasim reproduce scores the claims; the
// settings' dt_s and steps_per_period are the records'), whole steps per period (at least 8),
// target_periods periods. Throws InputError when it is too long.
struct SineGrid {
  StepGrid grid;
  long per_period = 0;
};
SineGrid sine_target_grid(const SineRun& run, const ObjectiveSettings& s);

// The run's drive on its grid (SineRun::drive_A), or nothing when the run has more than
// kMaxStoredDriveSteps steps (then each evaluation computes it as it goes).
constexpr long kMaxStoredDriveSteps = 1000000;
std::vector<double> sine_drive(const SineRun& run, const ObjectiveSettings& s);

// Runs the sine from the cached start state; the metrics are those of its last period, whose
// current, y [um] and B [T] are left in I, y, B (buffers reused across calls).
SineMetrics run_sine(const Model& m, const SineRun& run, const ObjectiveSettings& s,
                     std::vector<double>& I, std::vector<double>& y, std::vector<double>& B,
                     StartCache& starts);

// A DC run beside the sine runs in their lanes: the frf targets' bias settling
// (settle_at_bias_from's run_loop, gmasim/experiments/frf_bias.hpp): the state s advanced in
// place over grid at the held current I, under conditions c.
struct HeldRun {
  const Conditions* c = nullptr;
  State* s = nullptr;
  double I = 0;
  StepGrid grid;
};

// run_sine for every run (all of one model), the runs advancing together in SIMD lanes
// (gmasim/simulate/lanes.hpp; the model lanes_supported): the metrics in the order of runs.
// The held runs advance in lanes of the same batch, each state left as its last step leaves it.
// Throws the DivergenceError of the first run (in that order, the sines first) that diverges.
std::vector<SineMetrics> run_sines_lanes(const Model& m, const std::vector<SineRun>& runs,
                                         const ObjectiveSettings& s, StartCache& starts,
                                         const std::vector<HeldRun>& held = {});

// One point of a batch of sine runs across points (the candidates of a batch evaluation): its
// model (of the batch's structure), start states, held runs, and what the runs give.
struct SinePoint {
  const Model* m = nullptr;
  StartCache* starts = nullptr;
  std::vector<HeldRun> held;
  std::vector<SineMetrics> metrics;  // per run, when not failed
  bool failed = false;               // a run or held run of the point diverged
};
// run_sines_lanes for several points at once: sine k of point c in lane k P + c (a vector holds
// one sine across the points), then every point's held runs. Each point's metrics and held
// states are what run_sines_lanes(*m, runs, s, *starts, held) gives, bit for bit (each lane is
// the width-1 kernel's; no lane reads another). throw_first: the first divergence throws as
// above; else the point whose run diverges is failed and the others go on.
void run_sines_lanes(std::vector<SinePoint>& points, const std::vector<SineRun>& runs,
                     const ObjectiveSettings& s, bool throw_first);

// A resonance_Hz (lowest eq. 15 oscillator frequency at the bias), frf_peak_Hz or
// bandwidth_Hz (the small-signal frequency response of Fig. 15) target.
struct ResonanceRun {
  double T, bias;
  TargetKind kind;  // ResonanceHz, FrfPeakHz, BandwidthHz or ModulusGPa (at rest, no sine)
  bool operator==(const ResonanceRun&) const = default;
};
// The small-signal targets' bias point before its settling (settle_at_bias_from,
// gmasim/experiments/frf_bias.hpp): the conditions at the target's temperature, those of the
// ramp and the ramp's state, made with the start states in lanes (StartCache::make_in_lanes).
struct BiasRamp {
  Conditions c, ramp_c;
  State ramped;
  // ramped has run its DC settling already (settlings_beside_sines): settle_at_bias_from's
  // state but for its time.
  bool settled = false;
};

// The frf targets' bias ramps to make (those of kind frf_peak_Hz or bandwidth_Hz): ramps[k]'s
// conditions (at the target's temperature, and of its ramp) for res_runs[k]; the ramps'
// conditions, currents and indices k appended to rc, I0 and which, in that order (the
// arguments of StartCache::make_in_lanes).
void bias_ramps(const Model& model, const std::vector<ResonanceRun>& res_runs,
                std::deque<BiasRamp>& ramps, std::vector<const Conditions*>& rc,
                std::vector<double>& I0, std::vector<std::size_t>& which);

// The frf targets' DC settlings (ramps[k] for res_runs[k] of kind frf_peak_Hz or bandwidth_Hz)
// as held runs beside the sine runs, when they fit in the lanes the sines leave free (no more
// vectors of lanes_width() lanes) and in their length (no more steps): each such ramp's state
// set to bias_settling_start's in place and marked settled (run_sines_lanes then settles it).
// Otherwise nothing (the settlings run scalar in lowest_resonance_Hz).
std::vector<HeldRun> settlings_beside_sines(const Model& m, const std::vector<SineRun>& sines,
                                            const ObjectiveSettings& s,
                                            const std::vector<ResonanceRun>& res_runs,
                                            std::deque<BiasRamp>& ramps);

// The value of a target computed at rest or from the small-signal response (no sine run); the
// states at rest (modulus, resonance) are the cached ones at (T, bias). ramp: the bias point's
// ramp of a frf_peak_Hz or bandwidth_Hz target if made already (nullptr: settle_at_bias makes it).
double lowest_resonance_Hz(const Model& m, const ResonanceRun& run, StartCache& starts,
                           const BiasRamp* ramp = nullptr);

// run_record() from the record's start state: the cached one, or for a record measured at its
// own prestress (condition key prestress_MPa) the model with that preload (record_run.hpp,
// with_record_preload), started afresh.
void run_record_from_start(const Model& m, StartCache& starts, const Measurement& meas,
                           const ObjectiveSettings& s, std::vector<double>& response,
                           std::vector<double>* B_T);

}  // namespace gmasim::identify_detail
