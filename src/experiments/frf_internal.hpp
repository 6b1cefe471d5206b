// Internal: the pieces of gmasim frf shared by frf.cpp and frf_peak.cpp (the stepped-sine
// point, the adaptive refinement of its peak, the small-signal limit of the stimulus and the
// choice of the markers). docs/experiments.md, "Frequency response".
#pragma once

#include <cmath>
#include <complex>
#include <vector>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/run_loop.hpp"

namespace gmasim::detail {

// n frequencies from f0 to f1, evenly spaced in log f (frf_markers.cpp).
std::vector<double> log_grid(double f0, double f1, int n);

// The time grid of the stepped-sine point at fr Hz: >= r.min_steps_per_period steps per period
// with dt <= 10 us, settled for settling_time_s(lin) and >= r.settle_periods periods, then
// r.measure_periods periods measured (steps first+1 .. grid.steps, `measured` of them).
struct SteppedSineGrid {
  StepGrid grid;
  long first = 0, measured = 0;
};
SteppedSineGrid stepped_sine_grid(const SmallSignalModel& lin, const FrfRequest& r, double fr);

// A stepped-sine point's drive at t_s: the bias plus the amplitude's sine at f_Hz [A].
// The message of a stepped sine that diverged: its temperature, frequency, amplitude (named by
// its flag: a large --amplitude is the usual cause) and bias, then the run's diagnosis.
std::string stepped_sine_divergence(const FrfRequest& r, double temperature_C, double f_Hz,
                                    const std::string& why);
inline double stepped_sine_current_A(const FrfRequest& r, double f_Hz, double t_s) {
  return r.bias_A + r.amplitude_A * std::sin(2.0 * physics::kPi * f_Hz * t_s);
}

// first_harmonic_ratio's sums, one sample at a time (the scalar point sums its recorded
// samples, the lanes each lane's as it steps): y's and i's Fourier coefficient at f_Hz.
struct FirstHarmonicSums {
  std::complex<double> Y = 0.0, I = 0.0;
  void add(double t_s, double f_Hz, double y, double i) {
    const std::complex<double> e = std::polar(1.0, -2.0 * physics::kPi * f_Hz * t_s);
    Y += y * e;
    I += i * e;
  }
  std::complex<double> ratio() const { return Y / I; }
};

// One stepped-sine point at fr Hz from the settled bias state (frf.cpp).
std::complex<double> stepped_sine_point(const Model& m, const Conditions& c, const State& bias,
                                        const SmallSignalModel& lin, const FrfRequest& r,
                                        double fr);

// stepped_sine_point for every (temperature ti, frequency fi) of the grid, index ti * f.size()
// + fi, the points advancing together in SIMD lanes (frf_lanes.cpp; lanes_supported(m)):
// sorted by length, `lanes_width()` at a time, the batches over `threads` threads. Equal to the
// scalar points to the lanes' rounding; throws the DivergenceError of a diverged point.
std::vector<std::complex<double>> stepped_sine_points_lanes(
    const Model& m, const std::vector<Conditions>& conds, const std::vector<State>& bias,
    const std::vector<SmallSignalModel>& lin, const FrfRequest& r, const std::vector<double>& f,
    int threads, const ProgressFn& progress);

// A stepped-sine curve: frequencies (ascending) and Y/I [m/A].
struct SteppedCurve {
  std::vector<double> f_Hz;
  std::vector<std::complex<double>> Y;
};

// Golden-section search in ln f for the largest |Y/I| of the stepped sine between the grid
// neighbours of its largest local maximum (r.peak_refinements evaluations); the points it
// evaluated are merged into the curve. No local maximum in the band: the curve is unchanged.
void refine_stepped_peak(const Model& m, const Conditions& c, const State& bias,
                         const SmallSignalModel& lin, const FrfRequest& r, SteppedCurve& curve);

// The largest local maximum of mag over f (any spacing): the vertex of the parabola in ln f
// through it and its neighbours. {0, 0} when there is none.
struct Peak {
  double f_Hz = 0, mag = 0;
};
Peak data_peak(const std::vector<double>& f, const std::vector<double>& mag);

// Largest stimulus amplitude [A] for which the field excursion of every rod stays within
// kSmallSignalFraction of its reversible range (the law's reversible_field_range: JA's
// c k / (1 - c) of eq. 9, Preisach's smallest switching excursion): the static field gains
// dH_i/dI of the linearisation times the amplitude. Infinite when no rod has a finite range.
inline constexpr double kSmallSignalFraction = 0.1;
double small_signal_limit_A(const Model& m, const SmallSignalModel& lin, const Conditions& c);

// Sets cv's small-signal limit, large_signal flag, markers_from and the markers (resonance,
// bandwidth, the -3 dB reference gain) from the data the figure draws: the stepped sine when
// the stimulus is large (or the linearisation is off), the linearisation otherwise.
void choose_markers(FrfCurve& cv, const Model& m, const SmallSignalModel& lin, const Conditions& c,
                    const FrfRequest& r);

}  // namespace gmasim::detail
