// Design studies (issue 39, item 3): gmasim sweep --grid over model keys. Each design is the
// model recompiled with its values, so what they derive follows; its sweep equals a sweep of
// that model built by hand, and its derived columns equal the compiled model's.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "gmasim/experiments/design_sweep.hpp"
#include "gmasim/io/io.hpp"
#include "test_util.hpp"

using namespace gmasim;
using ::testing::HasSubstr;

namespace {

ModelSpec single_rod_spec() {
  return load_model_spec(std::string(GMASIM_SOURCE_DIR) + "/models/single_rod.toml");
}

SweepRequest small_sweep() {
  SweepRequest r;
  r.temperatures_C = {20, 70};
  r.currents_pp_A = {4};
  r.current_min_A = 0.0;  // the template has no bias magnet: a unipolar drive
  r.frequencies_Hz = {10};
  r.periods = 2;
  r.threads = 1;
  return r;
}

}  // namespace

TEST(DesignSweep, EachDesignIsTheModelRecompiledWithItsValues) {
  const ModelSpec base = single_rod_spec();
  const std::vector<GridAxis> axes = {{"rod.length_m", {0.05, 0.08}},
                                      {"circuit.branches.coil.coil_turns", {500, 800}}};
  const SweepRequest r = small_sweep();
  const DesignSweepResult res = run_design_sweep(base, axes, r);
  ASSERT_EQ(res.designs.size(), 4u);  // the first axis slowest
  EXPECT_EQ(res.designs[1].values, (std::vector<double>{0.05, 800}));
  EXPECT_EQ(res.designs[2].values, (std::vector<double>{0.08, 500}));
  for (const DesignPoint& d : res.designs) {
    ModelSpec spec = base;
    spec.set("rod.length_m", d.values[0]);
    spec.set("circuit.branches.coil.coil_turns", d.values[1]);
    const Model m = compile(spec);
    EXPECT_EQ(d.rods_mass_kg, m.rods[0].mass_kg);
    EXPECT_EQ(d.coil_resistance_ohm, m.thermal_network.coil_resistance_ohm);
    const SweepResult by_hand = run_sweep(m, r);
    ASSERT_EQ(d.sweep.points.size(), by_hand.points.size());
    for (std::size_t i = 0; i < by_hand.points.size(); ++i)
      EXPECT_EQ(d.sweep.points[i].metrics.stroke_um, by_hand.points[i].metrics.stroke_um);
    const LinearFrfMarkers lm = linear_frf_markers(m, r.reference_temperature_C, res.bias_A);
    EXPECT_EQ(d.bandwidth_Hz, lm.bandwidth_3dB_Hz);
  }
  // What follows from the geometry moves: the rod's mass with its length (density x volume),
  // the winding's resistance with its turns (a longer wire), and the stroke with both.
  EXPECT_NEAR(res.designs[2].rods_mass_kg / res.designs[0].rods_mass_kg, 0.08 / 0.05, 1e-12);
  EXPECT_NEAR(res.designs[1].coil_resistance_ohm / res.designs[0].coil_resistance_ohm,
              800.0 / 500.0, 1e-12);
  EXPECT_GT(res.designs[3].sweep.points[0].metrics.stroke_um,
            res.designs[0].sweep.points[0].metrics.stroke_um);
  // The report: the axes and derived columns beside each point, and one row per design.
  const Report rep = design_sweep_report(compile(base), r, res);
  const Table& pts = rep.tables.at(0);
  EXPECT_EQ(pts.columns.at(0), "rod.length_m");
  EXPECT_EQ(pts.rows.size(), 4u * 2u);
  EXPECT_EQ(rep.tables.back().name, "designs");
  EXPECT_EQ(rep.tables.back().rows.size(), 4u);
}

TEST(DesignSweep, BadGridsAreClearInputErrors) {
  const ModelSpec base = single_rod_spec();
  const SweepRequest r = small_sweep();
  auto msg = [&](std::vector<GridAxis> axes) {
    return gmasim_test::input_error([&] { (void)run_design_sweep(base, axes, r); });
  };
  EXPECT_THAT(msg({{"rod.colour_m", {1}}}), HasSubstr("--grid rod.colour_m: "));
  EXPECT_THAT(msg({{"rod.length_m", {0.05}}, {"rod.length_m", {0.06}}}), HasSubstr("given twice"));
  EXPECT_THAT(msg({{"rod.length_m", {}}}), HasSubstr("no values"));
  EXPECT_THAT(msg({{"rod.length_m", {0.05, -0.01}}}), HasSubstr("--grid rod.length_m=-0.01: "));
}
