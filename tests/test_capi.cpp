// The C API (gmasim/capi/gmasim_c.h) and the Stepper under it: stepping allocates nothing, is
// bit-identical to driving gmasim::step directly, and every error path returns its status
// code with a message naming the value and the rule.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "gmasim/capi/gmasim_c.h"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "gmasim/simulate/stepper.hpp"
#include "gmasim/version.h"

using ::testing::HasSubstr;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct ModelDeleter {
  void operator()(gmasim_model* m) const { gmasim_model_free(m); }
};
struct SimDeleter {
  void operator()(gmasim_sim* s) const { gmasim_sim_free(s); }
};
using ModelHandle = std::unique_ptr<gmasim_model, ModelDeleter>;
using SimHandle = std::unique_ptr<gmasim_sim, SimDeleter>;

ModelHandle builtin_handle() {
  gmasim_model* m = nullptr;
  EXPECT_EQ(gmasim_model_load(nullptr, &m), GMASIM_OK) << gmasim_last_error();
  return ModelHandle(m);
}

SimHandle make_sim(const gmasim_model* m, double T, double dt, double I0) {
  gmasim_sim* s = nullptr;
  EXPECT_EQ(gmasim_sim_create(m, T, dt, I0, &s), GMASIM_OK) << gmasim_last_error();
  return SimHandle(s);
}

double y_of(const gmasim_sim* s) {
  double y = kNaN;
  EXPECT_EQ(gmasim_sim_y_m(s, &y), GMASIM_OK);
  return y;
}

}  // namespace

TEST(CApi, VersionAndStatusNames) {
  EXPECT_STREQ(gmasim_version(), GMASIM_VERSION);
  EXPECT_STREQ(gmasim_git_describe(), GMASIM_GIT_DESCRIBE);
  EXPECT_STREQ(gmasim_status_name(GMASIM_OK), "GMASIM_OK");
  EXPECT_STREQ(gmasim_status_name(GMASIM_E_DIVERGED), "GMASIM_E_DIVERGED");
  EXPECT_STREQ(gmasim_status_name(42), "unknown status");
}

TEST(CApi, SimStepAllocatesNothing) {
  ModelHandle m = builtin_handle();
  SimHandle s = make_sim(m.get(), 70.0, 1e-5, -3.0);
  const gmasim::Waveform w = gmasim::biased_sine(8.0, 200.0);
  ASSERT_EQ(gmasim_sim_step(s.get(), w.current_at(1e-5)), GMASIM_OK);  // warm-up
  gmasim_outputs out;
  double y = 0.0, F = 0.0;
  long bad = 0;
  gmasim_test::g_allocations = 0;
  gmasim_test::g_counting = true;
  for (int k = 2; k <= 1001; ++k) {
    bad += gmasim_sim_step(s.get(), w.current_at(k * 1e-5)) != GMASIM_OK;
    bad += gmasim_sim_y_um(s.get(), &y) != GMASIM_OK;
    bad += gmasim_sim_rod_force_N(s.get(), 1, &F) != GMASIM_OK;
    bad += gmasim_sim_outputs(s.get(), &out) != GMASIM_OK;
  }
  gmasim_test::g_counting = false;
  EXPECT_EQ(bad, 0) << gmasim_sim_last_error(s.get());
  EXPECT_EQ(gmasim_test::g_allocations.load(), 0);
  EXPECT_EQ(out.steps, 1001);
  // The counter works: an allocation through the C API (a new sim) is seen.
  gmasim_test::g_counting = true;
  SimHandle other = make_sim(m.get(), 20.0, 1e-5, 0.0);
  gmasim_test::g_counting = false;
  EXPECT_GE(gmasim_test::g_allocations.load(), 1);
}

TEST(CApi, SteppingIsBitIdenticalToGmasimStep) {
  // The reference: gmasim::step driven as simulate() drives it (t = k dt, current at the end
  // of the step), over 0.1 s of a 10 Hz biased sine at 45 degC.
  const double dt = 1e-5, T = 45.0;
  const gmasim::Waveform w = gmasim::biased_sine(10.0, 10.0);
  const gmasim::Model model = gmasim::load_model("");
  const gmasim::Conditions c = gmasim::make_conditions(model, T);
  gmasim::State st = gmasim::make_state(model, c, w.current_at(0.0));

  ModelHandle m = builtin_handle();
  SimHandle s = make_sim(m.get(), T, dt, w.current_at(0.0));
  ASSERT_EQ(y_of(s.get()), st.y_m);
  int mismatches = 0;
  double y_min = 1.0, y_max = -1.0;
  for (long k = 1; k <= 10000; ++k) {
    const double t = static_cast<double>(k) * dt;
    gmasim::step(model, c, st, {w.current_at(t), dt});
    st.t_s = t;
    ASSERT_EQ(gmasim_sim_step(s.get(), w.current_at(t)), GMASIM_OK)
        << gmasim_sim_last_error(s.get());
    gmasim_outputs o;
    ASSERT_EQ(gmasim_sim_outputs(s.get(), &o), GMASIM_OK);
    mismatches += std::memcmp(&o.y_m, &st.y_m, sizeof(double)) != 0;
    mismatches += std::memcmp(&o.B_T, &st.B_T, sizeof(double)) != 0;
    mismatches += std::memcmp(&o.rod_F_N[2], &st.rods[2].F_N, sizeof(double)) != 0;
    mismatches += o.t_s != t;
    y_min = std::min(y_min, o.y_m);
    y_max = std::max(y_max, o.y_m);
  }
  EXPECT_EQ(mismatches, 0);
  // Not a trivial agreement: the output moved by tens of micrometres.
  EXPECT_GT((y_max - y_min) * 1e6, 10.0);
}

TEST(CApi, GettersReportTheState) {
  ModelHandle m = builtin_handle();
  int rods = 0;
  ASSERT_EQ(gmasim_model_rod_count(m.get(), &rods), GMASIM_OK);
  ASSERT_EQ(rods, 3);
  const char* name = nullptr;
  ASSERT_EQ(gmasim_model_rod_name(m.get(), 1, &name), GMASIM_OK);
  EXPECT_STREQ(name, "rod2");
  SimHandle s = make_sim(m.get(), 20.0, 2e-5, 1.5);
  for (int k = 0; k < 50; ++k) ASSERT_EQ(gmasim_sim_step(s.get(), 2.0), GMASIM_OK);
  gmasim_outputs o;
  ASSERT_EQ(gmasim_sim_outputs(s.get(), &o), GMASIM_OK);
  EXPECT_EQ(o.steps, 50);
  EXPECT_EQ(o.t_s, 50 * 2e-5);
  EXPECT_EQ(o.dt_s, 2e-5);
  EXPECT_EQ(o.current_A, 2.0);
  EXPECT_EQ(o.temperature_C, 20.0);
  EXPECT_EQ(o.rod_count, 3);
  EXPECT_EQ(o.diverged, 0);
  EXPECT_EQ(o.y_um, o.y_m * 1e6);
  EXPECT_EQ(o.rod_F_N[3], 0.0);
  for (int i = 0; i < 3; ++i) {
    double F = 0, lam = 0, M = 0;
    ASSERT_EQ(gmasim_sim_rod_force_N(s.get(), i, &F), GMASIM_OK);
    ASSERT_EQ(gmasim_sim_rod_strain(s.get(), i, &lam), GMASIM_OK);
    ASSERT_EQ(gmasim_sim_rod_magnetisation_A_per_m(s.get(), i, &M), GMASIM_OK);
    EXPECT_EQ(F, o.rod_F_N[i]);
    EXPECT_EQ(lam, o.rod_strain[i]);
    EXPECT_EQ(M, o.rod_M_A_per_m[i]);
    // A biased rod: magnetised and strained (a few hundred ppm at most).
    EXPECT_GT(M, 0.0);
    EXPECT_GT(lam, 0.0);
    EXPECT_LT(lam, 2e-3);
  }
  double t = 0, y = 0, yum = 0, B = 0, I = 0, T = 0, dt = 0;
  long n = 0;
  int rc = 0, div = 1;
  ASSERT_EQ(gmasim_sim_time_s(s.get(), &t), GMASIM_OK);
  ASSERT_EQ(gmasim_sim_y_m(s.get(), &y), GMASIM_OK);
  ASSERT_EQ(gmasim_sim_y_um(s.get(), &yum), GMASIM_OK);
  ASSERT_EQ(gmasim_sim_B_T(s.get(), &B), GMASIM_OK);
  ASSERT_EQ(gmasim_sim_current_A(s.get(), &I), GMASIM_OK);
  ASSERT_EQ(gmasim_sim_temperature_C(s.get(), &T), GMASIM_OK);
  ASSERT_EQ(gmasim_sim_dt_s(s.get(), &dt), GMASIM_OK);
  ASSERT_EQ(gmasim_sim_steps(s.get(), &n), GMASIM_OK);
  ASSERT_EQ(gmasim_sim_rod_count(s.get(), &rc), GMASIM_OK);
  ASSERT_EQ(gmasim_sim_diverged(s.get(), &div), GMASIM_OK);
  EXPECT_EQ(t, o.t_s);
  EXPECT_EQ(y, o.y_m);
  EXPECT_EQ(yum, o.y_um);
  EXPECT_EQ(B, o.B_T);
  EXPECT_EQ(I, 2.0);
  EXPECT_EQ(T, 20.0);
  EXPECT_EQ(dt, 2e-5);
  EXPECT_EQ(n, 50);
  EXPECT_EQ(rc, 3);
  EXPECT_EQ(div, 0);
}

TEST(CApi, ResetAndTemperatureChange) {
  ModelHandle m = builtin_handle();
  SimHandle s = make_sim(m.get(), 20.0, 1e-5, 0.0);
  std::vector<double> first, second;
  for (int k = 1; k <= 300; ++k) {
    ASSERT_EQ(gmasim_sim_step(s.get(), 4.0 * std::sin(k * 1e-2)), GMASIM_OK);
    first.push_back(y_of(s.get()));
  }
  ASSERT_EQ(gmasim_sim_reset(s.get(), 0.0), GMASIM_OK);
  double t = 1.0;
  ASSERT_EQ(gmasim_sim_time_s(s.get(), &t), GMASIM_OK);
  EXPECT_EQ(t, 0.0);
  for (int k = 1; k <= 300; ++k) {
    ASSERT_EQ(gmasim_sim_step(s.get(), 4.0 * std::sin(k * 1e-2)), GMASIM_OK);
    second.push_back(y_of(s.get()));
  }
  EXPECT_EQ(first, second);  // deterministic: the same bits after a reset

  // A hotter actuator under the same current: a different quasi-static output; the state, time
  // and step count carry on.
  const double y20 = y_of(s.get());
  ASSERT_EQ(gmasim_sim_set_temperature(s.get(), 90.0), GMASIM_OK);
  double T = 0;
  ASSERT_EQ(gmasim_sim_temperature_C(s.get(), &T), GMASIM_OK);
  EXPECT_EQ(T, 90.0);
  const double I = 4.0 * std::sin(300 * 1e-2);
  for (int k = 0; k < 2000; ++k) ASSERT_EQ(gmasim_sim_step(s.get(), I), GMASIM_OK);
  long n = 0;
  ASSERT_EQ(gmasim_sim_steps(s.get(), &n), GMASIM_OK);
  EXPECT_EQ(n, 2300);
  EXPECT_GT(std::fabs(y_of(s.get()) - y20) * 1e6, 0.1);
}

TEST(CApi, NullHandlesAndPointersAreArgumentErrors) {
  double v = 0;
  int i = 0;
  EXPECT_EQ(gmasim_sim_step(nullptr, 1.0), GMASIM_E_ARGUMENT);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("gmasim_sim_step: sim is NULL"));
  EXPECT_EQ(gmasim_sim_y_m(nullptr, &v), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_sim_reset(nullptr, 0.0), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_sim_set_temperature(nullptr, 20.0), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_sim_outputs(nullptr, nullptr), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_model_rod_count(nullptr, &i), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_model_load("", nullptr), GMASIM_E_ARGUMENT);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("gmasim_model_load: out is NULL"));
  EXPECT_EQ(gmasim_model_load_string(nullptr, "x", nullptr), GMASIM_E_ARGUMENT);
  EXPECT_STREQ(gmasim_sim_last_error(nullptr), "");
  EXPECT_STREQ(gmasim_model_last_error(nullptr), "");
  gmasim_sim_free(nullptr);
  gmasim_model_free(nullptr);

  gmasim_sim* s = reinterpret_cast<gmasim_sim*>(0x1);
  EXPECT_EQ(gmasim_sim_create(nullptr, 20.0, 1e-5, 0.0, &s), GMASIM_E_ARGUMENT);
  EXPECT_EQ(s, nullptr);  // *out is cleared on failure
  EXPECT_THAT(gmasim_last_error(), HasSubstr("model is NULL"));

  ModelHandle m = builtin_handle();
  SimHandle sim = make_sim(m.get(), 20.0, 1e-5, 0.0);
  EXPECT_EQ(gmasim_sim_y_m(sim.get(), nullptr), GMASIM_E_ARGUMENT);
  EXPECT_THAT(gmasim_sim_last_error(sim.get()), HasSubstr("gmasim_sim_y_m: out is NULL"));
  EXPECT_EQ(gmasim_sim_rod_force_N(sim.get(), 3, &v), GMASIM_E_ARGUMENT);
  EXPECT_THAT(gmasim_sim_last_error(sim.get()), HasSubstr("rod index 3: out of range [0, 3)"));
  EXPECT_EQ(gmasim_sim_rod_strain(sim.get(), -1, &v), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_sim_rod_magnetisation_A_per_m(sim.get(), 7, &v), GMASIM_E_ARGUMENT);
  const char* name = nullptr;
  EXPECT_EQ(gmasim_model_rod_name(m.get(), 3, &name), GMASIM_E_ARGUMENT);
  EXPECT_THAT(gmasim_model_last_error(m.get()), HasSubstr("rod index 3"));
}

// Issue 19, item 12: a freed handle, a handle of the other type or a forged one is refused with
// GMASIM_E_ARGUMENT; a double free is an error code, not an abort in glibc. Many handles made
// and freed from several threads stay distinct and live exactly until freed.
TEST(CApi, FreedAndUnknownHandlesAreErrorCodes) {
  gmasim_model* m = nullptr;
  ASSERT_EQ(gmasim_model_load(nullptr, &m), GMASIM_OK);
  gmasim_sim* s = nullptr;
  ASSERT_EQ(gmasim_sim_create(m, 20.0, 1e-5, 0.0, &s), GMASIM_OK);
  EXPECT_EQ(gmasim_model_free(m), GMASIM_OK);
  EXPECT_EQ(gmasim_model_free(m), GMASIM_E_ARGUMENT);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("gmasim_model_free: model = "));
  EXPECT_THAT(gmasim_last_error(), HasSubstr("not a live gmasim_model handle (freed already"));
  int n = 0;
  EXPECT_EQ(gmasim_model_rod_count(m, &n), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_sim_step(s, 1.0), GMASIM_OK);  // the sim keeps its model alive
  EXPECT_EQ(gmasim_sim_free(s), GMASIM_OK);
  double v = 0.0;
  EXPECT_EQ(gmasim_sim_y_m(s, &v), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_sim_free(s), GMASIM_E_ARGUMENT);
  EXPECT_STRNE(gmasim_sim_last_error(s), "");
  EXPECT_EQ(gmasim_sim_free(reinterpret_cast<gmasim_sim*>(0x1)), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_model_free(reinterpret_cast<gmasim_model*>(&v)), GMASIM_E_ARGUMENT);

  std::vector<std::thread> pool;
  std::atomic<int> bad{0};
  for (int t = 0; t < 4; ++t)
    pool.emplace_back([&bad] {
      std::vector<gmasim_model*> mine;
      for (int k = 0; k < 50; ++k) {
        gmasim_model* h = nullptr;
        if (gmasim_model_load(nullptr, &h) != GMASIM_OK) ++bad;
        mine.push_back(h);
        if (k % 3 == 0) {  // free some early: their slots are reused by later loads
          if (gmasim_model_free(h) != GMASIM_OK) ++bad;
          if (gmasim_model_free(h) != GMASIM_E_ARGUMENT) ++bad;
          mine.back() = nullptr;
        }
      }
      for (gmasim_model* h : mine) {
        int rods = 0;
        if (h && (gmasim_model_rod_count(h, &rods) != GMASIM_OK || rods != 3)) ++bad;
        if (gmasim_model_free(h) != GMASIM_OK) ++bad;
      }
    });
  for (auto& th : pool) th.join();
  EXPECT_EQ(bad.load(), 0);
}

TEST(CApi, BadNumbersAreRefusedAndLeaveTheSimUntouched) {
  ModelHandle m = builtin_handle();
  SimHandle s = make_sim(m.get(), 20.0, 1e-5, 0.0);
  ASSERT_EQ(gmasim_sim_step(s.get(), 1.0), GMASIM_OK);
  gmasim_outputs before, after;
  ASSERT_EQ(gmasim_sim_outputs(s.get(), &before), GMASIM_OK);

  EXPECT_EQ(gmasim_sim_step(s.get(), kNaN), GMASIM_E_ARGUMENT);
  EXPECT_THAT(gmasim_sim_last_error(s.get()),
              HasSubstr("gmasim_sim_step: coil current = nan A: must be a finite number"));
  EXPECT_EQ(gmasim_sim_step(s.get(), INFINITY), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_sim_step(s.get(), 1500.0), GMASIM_E_INPUT);
  EXPECT_THAT(gmasim_sim_last_error(s.get()), HasSubstr("coil current"));
  EXPECT_THAT(gmasim_sim_last_error(s.get()), HasSubstr("1500"));
  EXPECT_THAT(gmasim_sim_last_error(s.get()), HasSubstr("1000"));
  EXPECT_EQ(gmasim_sim_reset(s.get(), kNaN), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_sim_set_temperature(s.get(), kNaN), GMASIM_E_ARGUMENT);
  // At the Curie point (material.Tc_C of the built-in model, 380 degC) and above.
  EXPECT_EQ(gmasim_sim_set_temperature(s.get(), 380.0), GMASIM_E_INPUT);
  EXPECT_THAT(gmasim_sim_last_error(s.get()), HasSubstr("Curie"));
  // The thread's message is the same failure.
  EXPECT_THAT(gmasim_last_error(), HasSubstr("gmasim_sim_set_temperature: temperature 380 degC"));
  ASSERT_EQ(gmasim_sim_outputs(s.get(), &after), GMASIM_OK);
  EXPECT_EQ(std::memcmp(&before, &after, sizeof before), 0);
  // Still alive: the next good step works.
  EXPECT_EQ(gmasim_sim_step(s.get(), 1.0), GMASIM_OK);

  gmasim_sim* bad = nullptr;
  EXPECT_EQ(gmasim_sim_create(m.get(), 1e4, 1e-5, 0.0, &bad), GMASIM_E_INPUT);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("Curie"));
  EXPECT_EQ(gmasim_sim_create(m.get(), -300.0, 1e-5, 0.0, &bad), GMASIM_E_INPUT);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("absolute zero"));
  EXPECT_EQ(gmasim_sim_create(m.get(), kNaN, 1e-5, 0.0, &bad), GMASIM_E_ARGUMENT);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("temperature = nan degC: must be a finite number"));
  EXPECT_EQ(gmasim_sim_create(m.get(), 20.0, 0.0, 0.0, &bad), GMASIM_E_INPUT);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("time step dt = 0 s: must be > 0"));
  EXPECT_EQ(gmasim_sim_create(m.get(), 20.0, 2e-3, 0.0, &bad), GMASIM_E_INPUT);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("time step dt = 0.002 s: must be <= 0.001 s"));
  EXPECT_EQ(gmasim_sim_create(m.get(), 20.0, -INFINITY, 0.0, &bad), GMASIM_E_ARGUMENT);
  EXPECT_EQ(gmasim_sim_create(m.get(), 20.0, 1e-5, -1001.0, &bad), GMASIM_E_INPUT);
  EXPECT_EQ(bad, nullptr);
}

TEST(CApi, BadModelsNameTheFile) {
  gmasim_model* m = reinterpret_cast<gmasim_model*>(0x1);
  EXPECT_EQ(gmasim_model_load("/no/such/dir/actuator.toml", &m), GMASIM_E_INPUT);
  EXPECT_EQ(m, nullptr);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("gmasim_model_load: "));
  EXPECT_THAT(gmasim_last_error(), HasSubstr("/no/such/dir/actuator.toml"));

  EXPECT_EQ(gmasim_model_load_string("[stack]\nrods = 3\n", "my.toml", &m), GMASIM_E_INPUT);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("my.toml"));
  EXPECT_EQ(gmasim_model_load_string("not toml ][", nullptr, &m), GMASIM_E_INPUT);
  EXPECT_THAT(gmasim_last_error(), HasSubstr("<string>"));

  // The built-in text loads the same model as the built-in path.
  ASSERT_EQ(gmasim_model_load_string(gmasim::kBuiltinModelToml, "mdma.toml", &m), GMASIM_OK);
  ModelHandle from_text(m);
  ModelHandle from_path = builtin_handle();
  SimHandle a = make_sim(from_text.get(), 60.0, 1e-5, 2.0);
  SimHandle b = make_sim(from_path.get(), 60.0, 1e-5, 2.0);
  for (int k = 0; k < 100; ++k) {
    ASSERT_EQ(gmasim_sim_step(a.get(), 3.0), GMASIM_OK);
    ASSERT_EQ(gmasim_sim_step(b.get(), 3.0), GMASIM_OK);
  }
  EXPECT_EQ(y_of(a.get()), y_of(b.get()));
}

TEST(CApi, DivergenceStopsTheSimUntilReset) {
  // An absurd coil (7.2e9 turns, as in Numerics.DivergenceNames...) and the largest current.
  std::string text = gmasim::kBuiltinModelToml;
  const std::string turns = "coil_turns = 720.0";
  const auto at = text.find(turns);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, turns.size(), "coil_turns = 7.2e9");
  gmasim_model* raw = nullptr;
  ASSERT_EQ(gmasim_model_load_string(text.c_str(), "absurd.toml", &raw), GMASIM_OK)
      << gmasim_last_error();
  ModelHandle m(raw);
  SimHandle s = make_sim(m.get(), 20.0, 1e-5, 1e-6);
  int rc = GMASIM_OK;
  int k = 0;
  for (; k < 200 && rc == GMASIM_OK; ++k) rc = gmasim_sim_step(s.get(), 1000.0);
  ASSERT_EQ(rc, GMASIM_E_DIVERGED);
  const std::string first = gmasim_sim_last_error(s.get());
  EXPECT_THAT(first, HasSubstr("gmasim_sim_step: diverged at t = "));
  int div = 0;
  ASSERT_EQ(gmasim_sim_diverged(s.get(), &div), GMASIM_OK);
  EXPECT_EQ(div, 1);
  // Refused, with the first divergence in the message, however small the next current.
  EXPECT_EQ(gmasim_sim_step(s.get(), 0.0), GMASIM_E_DIVERGED);
  EXPECT_THAT(gmasim_sim_last_error(s.get()), HasSubstr("refused: the sim diverged earlier"));
  EXPECT_THAT(gmasim_sim_last_error(s.get()), HasSubstr("gmasim_sim_reset"));
  EXPECT_THAT(gmasim_sim_last_error(s.get()), HasSubstr(first.substr(first.find("diverged at"))));
  // Getters still answer; reset brings it back.
  ASSERT_EQ(gmasim_sim_reset(s.get(), 0.0), GMASIM_OK);
  ASSERT_EQ(gmasim_sim_diverged(s.get(), &div), GMASIM_OK);
  EXPECT_EQ(div, 0);
  EXPECT_EQ(gmasim_sim_step(s.get(), 0.0), GMASIM_OK);
}

TEST(Stepper, CppStepperMatchesSimulate) {
  // The C++ session under both APIs reproduces simulate()'s recorded output bit for bit.
  auto model = std::make_shared<const gmasim::Model>(gmasim::load_model(""));
  gmasim::SimulationSettings set;
  set.temperature_C = 70.0;
  set.waveform = gmasim::biased_sine(8.0, 50.0);
  set.periods = 2.0;
  const gmasim::Result r = gmasim::simulate(*model, set);
  ASSERT_FALSE(r.diverged);
  const auto& I = r.series.column("current_A");
  const auto& y = r.series.column("y_um");
  gmasim::Stepper st(model, 70.0, r.dt_s, I[0]);
  EXPECT_EQ(st.y_m() * 1e6, y[0]);
  int mismatches = 0;
  for (std::size_t k = 1; k < I.size(); ++k) mismatches += st.step(I[k]) * 1e6 != y[k];
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(st.t_s(), r.series.column("t_s").back());
  // The C++ errors: the types the C API maps to its codes.
  EXPECT_THROW(st.step(kNaN), gmasim::InputError);
  EXPECT_THROW(gmasim::Stepper(nullptr, 20.0, 1e-5), gmasim::InputError);
  EXPECT_THROW(gmasim::Stepper(model, 20.0, 1e-2), gmasim::InputError);
}
