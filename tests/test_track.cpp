// The discrete PID, closed-loop tracking (Fig. 16, src/experiments/track.cpp) and the
// temperature compensation (src/experiments/compensate.cpp). Numbers, not plumbing;
// tolerances are about 10x the residual observed on this model (noted at each check).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "experiments_fixtures.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/compensate.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/experiments/reproduce.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "gmasim/simulate/simulate.hpp"

using namespace gmasim;
using namespace gmasim_experiments_test;

// ---------------------------------------------------------------------------------------
// PID and closed-loop tracking
// ---------------------------------------------------------------------------------------
namespace {

// First-order linear plant tau dy/dt = K u - y, exact zero-order-hold discretisation.
struct FirstOrderPlant {
  double K, tau, Ts, y = 0.0;
  double step(double u) {
    const double a = std::exp(-Ts / tau);
    y = a * y + (1 - a) * K * u;
    return y;
  }
};

}  // namespace

TEST(Pid, SteadyStateErrorVanishesOnALinearPlant) {
  const double fs = 10000.0;
  // A plant like the actuator's large-signal slope: 7 um/A, 0.5 ms lag.
  FirstOrderPlant plant{7.0, 5e-4, 1.0 / fs};
  Pid pid(PidGains{}, fs, -100.0, 100.0);
  const double ref = 10.0;  // um
  double e = ref;
  for (int k = 0; k < 4000; ++k) {
    e = ref - plant.y;
    plant.step(pid.update(e));
  }
  EXPECT_LT(std::fabs(ref - plant.y), 1e-9);
  EXPECT_NEAR(pid.integral_sum() * 0.03, ref / 7.0, 1e-9);  // the integrator holds u = r/K
  // P only: the analytic steady-state error r / (1 + kp K).
  FirstOrderPlant p2{7.0, 5e-4, 1.0 / fs};
  Pid ponly(PidGains{0.2, 0.0, 0.0, fs}, fs, -100.0, 100.0);
  for (int k = 0; k < 4000; ++k) p2.step(ponly.update(ref - p2.y));
  EXPECT_NEAR(ref - p2.y, ref / (1.0 + 0.2 * 7.0), 1e-9);
}

TEST(Pid, GainsDescribeTheSameControllerAtAnySampleRate) {
  // ki, kd are per-sample at the gains' reference rate (10 kHz): at 20 kHz the same
  // constant error for the same time integrates to the same output.
  Pid a(PidGains{0.0, 0.03, 0.0, 10000.0}, 10000.0, -1e9, 1e9);
  Pid b(PidGains{0.0, 0.03, 0.0, 10000.0}, 20000.0, -1e9, 1e9);
  double ua = 0, ub = 0;
  for (int k = 0; k < 10000; ++k) ua = a.update(1.0);  // 1 s
  for (int k = 0; k < 20000; ++k) ub = b.update(1.0);  // 1 s
  EXPECT_NEAR(ua, 300.0, 1e-9);                        // ki * rate * t * e
  EXPECT_NEAR(ub, 300.0, 1e-9);
  // Derivative: a ramp e = t [um/s] gives kd * rate_ref * de/dt at both rates.
  Pid da(PidGains{0.0, 0.0, 0.007, 10000.0}, 10000.0, -1e9, 1e9);
  Pid db(PidGains{0.0, 0.0, 0.007, 10000.0}, 20000.0, -1e9, 1e9);
  da.update(0.0);
  db.update(0.0);
  EXPECT_NEAR(da.update(1e-4), 0.007 / 10000.0 * 1.0, 1e-15);  // Kd = kd / rate_ref [A s/um]
  EXPECT_NEAR(db.update(5e-5), 0.007 / 10000.0 * 1.0, 1e-15);
}

TEST(Pid, OutputIsClippedWithoutWindUp) {
  Pid pid(PidGains{0.2, 0.03, 0.0, 10000.0}, 10000.0, -2.0, 2.0);
  for (int k = 0; k < 1000; ++k) EXPECT_LE(pid.update(50.0), 2.0);
  const double held = pid.integral_sum();
  EXPECT_LT(held * 0.03, 3.0);  // the sum stopped growing once the output clipped
  // A reversed error leaves saturation at once instead of unwinding a huge sum.
  EXPECT_LT(pid.update(-20.0), 2.0);
}

TEST(Track, ClosedLoopTracksAndIsDeterministic) {
  const Model& m = mdma();
  TrackRequest r;
  r.temperatures_C = {20, 70};
  r.amplitudes_um = {10};
  r.frequencies_Hz = {10};
  r.periods = 2;
  r.threads = 1;
  const TrackResult a = run_track(m, r);
  ASSERT_EQ(a.points.size(), 2u);
  for (const auto& p : a.points) {
    EXPECT_FALSE(p.diverged) << p.error;
    EXPECT_FALSE(p.saturated);
    EXPECT_LT(p.error_rms_um, 0.5);  // observed 0.19 / 0.20 um: 2 % of the amplitude
    EXPECT_GT(p.error_rms_um, 0.01);
    EXPECT_GE(p.error_peak_um, p.error_rms_um);
  }
  EXPECT_EQ(a.points[0].error_change_pct, 0.0);
  EXPECT_GT(a.points[1].error_change_pct, 0.0);  // hotter: less stroke per ampere, more error
  // The example series is the first point, sampled at the controller rate.
  EXPECT_EQ(a.example.names[1], "reference_um");
  EXPECT_EQ(a.example.rows(), static_cast<std::size_t>(std::lround(2 * 0.1 * r.sample_rate_Hz)));
  r.threads = 2;
  const TrackResult b = run_track(m, r);
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i].error_rms_um, b.points[i].error_rms_um);
    EXPECT_EQ(a.points[i].error_peak_um, b.points[i].error_peak_um);
  }
  // Sensor noise from a seeded generator: reproducible, and it adds error.
  r.sensor_noise_um = 1.0;
  const TrackResult n1 = run_track(m, r), n2 = run_track(m, r);
  EXPECT_EQ(n1.points[0].error_rms_um, n2.points[0].error_rms_um);
  EXPECT_GT(n1.points[0].error_rms_um, a.points[0].error_rms_um);
}

// Why the gains are per sample at 10 kHz (docs/experiments.md): read as continuous gains
// with time in seconds (ki 0.03 A/(um s), kd 0.007 A s/um) the loop is unstable.
TEST(Track, ContinuousSecondsReadingOfTheGainsIsUnstable) {
  TrackRequest r;
  r.temperatures_C = {20};
  r.amplitudes_um = {10};
  r.frequencies_Hz = {10};
  r.periods = 1;
  r.gains = PidGains{0.2, 0.03 / 10000.0, 0.007 * 10000.0, 10000.0};
  const TrackResult res = run_track(mdma(), r);
  EXPECT_TRUE(res.points[0].saturated);
  EXPECT_GT(res.points[0].error_rms_um, r.amplitudes_um[0]);
}

TEST(Track, BadRequestsAreClearInputErrors) {
  const Model& m = mdma();
  auto run = [&](auto edit) {
    return input_error_of([&] {
      TrackRequest r;
      r.temperatures_C = {20};
      r.periods = 1;
      edit(r);
      run_track(m, r);
    });
  };
  EXPECT_NE(run([](TrackRequest& r) {
              r.sample_rate_Hz = 150;
              r.frequencies_Hz = {10, 100};
            }).find("below twice the reference frequency 100 Hz"),
            std::string::npos);
  EXPECT_NE(run([](TrackRequest& r) { r.frequencies_Hz = {0}; }).find("must be > 0"),
            std::string::npos);
  EXPECT_NE(run([](TrackRequest& r) { r.temperatures_C = {400}; }).find("Curie"),
            std::string::npos);
  EXPECT_NE(run([](TrackRequest& r) { r.bias_A = 20; }).find("inside the current limit"),
            std::string::npos);
}

// ---------------------------------------------------------------------------------------
// Temperature compensation (issue 9, item 2)
// ---------------------------------------------------------------------------------------
TEST(Compensate, SolvedDriveRestoresTheTargetStrokeInEveryMode) {
  const gmasim::Model m = gmasim::load_model("");
  for (auto adjust : {gmasim::CompensationAdjust::Amplitude, gmasim::CompensationAdjust::Swing,
                      gmasim::CompensationAdjust::Scale}) {
    gmasim::CompensateRequest r;
    r.temperatures_C = {20.0, 90.0};
    // 5 A p-p: below the built-in model's saturation (at 6 A the 90 degC stroke needs 30 A;
    // at 4 A issue 37's model strokes more when hot, so nothing is lost to restore).
    r.reference_current_pp_A = 5.0;
    r.adjust = adjust;
    r.periods = 2.0;
    r.tolerance_um = 1e-3;
    const auto res = gmasim::run_compensate(m, r);
    ASSERT_EQ(res.points.size(), 2u);
    EXPECT_NEAR(res.points[0].gain, 1.0, 1e-9);  // the reference temperature needs no change
    const auto& hot = res.points[1];
    ASSERT_TRUE(hot.reachable && !hot.diverged) << hot.error;
    EXPECT_NEAR(hot.stroke_um, res.target_stroke_um, r.tolerance_um);
    EXPECT_LT(hot.uncompensated_stroke_um, res.target_stroke_um - 1.0);  // it was lost
    EXPECT_GT(hot.gain, 1.02);  // the drive grew (amplitude: 1.40 on issue 37's model)
    // The drive, rerun independently, gives that stroke.
    gmasim::SimulationSettings s;
    s.temperature_C = 90.0;
    s.waveform = gmasim::biased_sine(hot.current_pp_A, r.frequency_Hz, hot.current_min_A);
    s.periods = r.periods;
    EXPECT_NEAR(gmasim::simulate(m, s).metrics.stroke_um, hot.stroke_um, 1e-9);
    EXPECT_LT(hot.evaluations, 30);
  }
}

TEST(Compensate, UnreachableTargetsAndBadRequestsAreReported) {
  const gmasim::Model m = gmasim::load_model("");
  gmasim::CompensateRequest r;
  r.temperatures_C = {150.0};
  r.max_current_A = 6.0;  // the reference 5 A peak fits, the hot drive does not
  r.periods = 2.0;
  r.lower_target_to_reach = false;  // the reference's stroke, reachable or not
  const auto res = gmasim::run_compensate(m, r);
  EXPECT_FALSE(res.points[0].reachable);
  EXPECT_NEAR(res.points[0].current_max_A, 6.0, 1e-12);
  EXPECT_LT(res.points[0].stroke_um, res.target_stroke_um);
  auto refused = [&](auto edit, const char* what) {
    gmasim::CompensateRequest q;
    q.temperatures_C = {20.0};
    edit(q);
    EXPECT_THROW(
        {
          try {
            (void)gmasim::run_compensate(m, q);
          } catch (const gmasim::InputError& e) {
            EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr(what));
            throw;
          }
        },
        gmasim::InputError);
  };
  refused([](auto& q) { q.temperatures_C = {20.0, std::nan("")}; }, "temperature");
  refused([](auto& q) { q.temperatures_C = {400.0}; }, "Curie");
  refused([](auto& q) { q.temperatures_C = {70.0, 20.0}; }, "must increase");
  refused([](auto& q) { q.max_current_A = 4.0; }, "beyond the maximum current");
  refused([](auto& q) { q.max_current_A = 2.0; },
          "current minimum (--current-min) = -3 A: must be in");
  refused([](auto& q) { q.reference_current_pp_A = 0.0; }, "must be > 0");
  refused([](auto& q) { q.target_stroke_um = 1e300; }, "target stroke");
  refused([](auto& q) { q.tolerance_um = 0.0; }, "stroke tolerance");
}

TEST(Compensate, UnitFeedforwardIsThePlainPid) {
  // g = 1 everywhere and no reference feed-forward: the same loop, to the last bit, as long
  // as the current does not clip.
  const gmasim::Model m = gmasim::load_model("");
  gmasim::TrackRequest t;
  t.temperatures_C = {20.0, 70.0};
  t.amplitudes_um = {10.0};
  t.frequencies_Hz = {10.0};
  t.periods = 2.0;
  const auto plain = gmasim::run_track(m, t);
  t.feedforward.temperatures_C = {20.0, 70.0};
  t.feedforward.gains = {1.0, 1.0};
  const auto unit = gmasim::run_track(m, t);
  for (std::size_t i = 0; i < plain.points.size(); ++i) {
    ASSERT_FALSE(plain.points[i].saturated);
    EXPECT_EQ(plain.points[i].error_rms_um, unit.points[i].error_rms_um);
  }
  EXPECT_DOUBLE_EQ(t.feedforward.gain_at(45.0), 1.0);
  t.feedforward.gains = {1.0, 2.0};
  EXPECT_DOUBLE_EQ(t.feedforward.gain_at(45.0), 1.5);
  EXPECT_DOUBLE_EQ(t.feedforward.gain_at(-10.0), 1.0);  // held beyond the ends
  EXPECT_DOUBLE_EQ(t.feedforward.gain_at(900.0), 2.0);
  t.feedforward.gains = {1.0};
  EXPECT_THROW((void)gmasim::run_track(m, t), gmasim::InputError);
}
