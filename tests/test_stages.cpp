// step() in named stages (gmasim/model/step_stages.hpp, issue 21): the stages called one by one
// advance a state exactly as step() does, for both readings of the magnetic state, with the
// energy ledgers booked, and with each magnetisation law.
#include <gtest/gtest.h>

#include <string>

#include "gmasim/io.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model.hpp"
#include "gmasim/model/step_stages.hpp"
#include "gmasim/simulate.hpp"

using namespace gmasim;

namespace {

// The stages in their one order (physics::run_stages), each the public stage function.
template <class Law>
void staged_step(const Model& m, const Conditions& c, State& s, const StepInput& in) {
  ScalarStages<Law> st(m, c, s, in);
  physics::run_stages(st);
}

// Runs 300 steps of an 8 A, 400 Hz biased sine both ways; every output and ledger sum equal.
template <class Law>
void expect_stages_are_the_step(const Model& m, bool ledger) {
  const Conditions c = make_conditions(m, 70.0);
  const Waveform w = biased_sine(8.0, 400.0);
  State a = make_state(m, c, w.current_at(0.0));
  a.energy.enabled = ledger;
  State b = a;
  const double dt = auto_dt(w);
  for (int k = 1; k <= 300; ++k) {
    const StepInput in{w.current_at(k * dt), dt};
    step(m, c, a, in);
    staged_step<Law>(m, c, b, in);
  }
  EXPECT_EQ(a.t_s, b.t_s);
  EXPECT_EQ(a.y_m, b.y_m);
  EXPECT_EQ(a.B_T, b.B_T);
  for (std::size_t i = 0; i < a.rods.size(); ++i) {
    EXPECT_EQ(a.rods[i].H_A_per_m, b.rods[i].H_A_per_m) << i;
    EXPECT_EQ(a.rods[i].M_A_per_m, b.rods[i].M_A_per_m) << i;
    EXPECT_EQ(a.rods[i].x_m, b.rods[i].x_m) << i;
    EXPECT_EQ(a.rods[i].v_m_per_s, b.rods[i].v_m_per_s) << i;
    EXPECT_EQ(a.rods[i].F_N, b.rods[i].F_N) << i;
    EXPECT_EQ(a.rods[i].energy.hysteresis_J, b.rods[i].energy.hysteresis_J) << i;
    EXPECT_EQ(a.rods[i].energy.damping_J, b.rods[i].energy.damping_J) << i;
  }
  EXPECT_EQ(a.energy.coil_J, b.energy.coil_J);
  EXPECT_EQ(a.energy.magnet_J, b.energy.magnet_J);
  if (ledger) {
    EXPECT_NE(a.energy.coil_J, 0.0);  // the ledger stage booked
  }
}

}  // namespace

TEST(Stages, CalledOneByOneTheyAreTheStep) {
  const Model builtin = load_model("");
  expect_stages_are_the_step<JilesAthertonLaw>(builtin, false);
  expect_stages_are_the_step<JilesAthertonLaw>(builtin, true);
  const Model printed = load_model(std::string(GMASIM_SOURCE_DIR) + "/models/mdma_printed.toml");
  expect_stages_are_the_step<JilesAthertonLaw>(printed, true);
  const Model preisach =
      load_model(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod_preisach.toml");
  expect_stages_are_the_step<PreisachLaw>(preisach, true);
}
