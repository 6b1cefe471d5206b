// Design studies (issue 39, item 3): the sweep's temperature x current x frequency grid crossed
// with a grid over any model keys (`gmasim sweep --grid KEY=v1,v2,...`). Each combination of
// the keys' values is a design: the model's spec with those values set, compiled again, so
// that everything derived from them follows (masses, reluctances, coil resistance, the rods'
// stiffness); its derived quantities are reported beside its sweep.
#pragma once

#include <string>
#include <vector>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/model/model.hpp"

namespace gmasim {

// One key of the design grid and its values, in the key's unit (the model file's).
struct GridAxis {
  std::string key;
  std::vector<double> values;
};

// What a design is, beside its sweep: the rods' mass (the sum of rods' mass_kg) [kg], the coil's
// resistance at T_ref [ohm], and the small-signal first resonance and -3 dB bandwidth at the
// sweep's reference temperature about the FRF's default bias (linear_frf_markers) [Hz].
struct DesignPoint {
  std::vector<double> values;  // one per axis, in the axes' order
  double rods_mass_kg = 0, coil_resistance_ohm = 0;
  double first_resonance_Hz = 0, bandwidth_Hz = 0;
  SweepResult sweep;
  // The coil's copper loss I_rms^2 R(T) of each point's drive (coil_copper_loss_W) [W], in the
  // order of sweep.points, then of sweep.reference_points.
  std::vector<double> copper_loss_W, reference_copper_loss_W;
};

struct DesignSweepResult {
  std::vector<GridAxis> axes;
  std::vector<DesignPoint> designs;  // the axes' cartesian product, the first axis slowest
  double bias_A = 0;                 // of the small-signal markers
  double wall_time_s = 0;
};

// Throws InputError for an empty axis, a repeated key, a key the model does not have (named
// with --grid), a value the key's rule refuses, or more than kMaxListValues designs.
// With ranks > 1 only the designs d with d mod ranks == rank run (each is still compiled and
// checked); the others keep their values and nothing else (identify's run_design_sweep_ranks
// gathers them from the ranks that ran them).
DesignSweepResult run_design_sweep(const ModelSpec& base, const std::vector<GridAxis>& axes,
                                   const SweepRequest& r, const ProgressFn& progress = {},
                                   int rank = 0, int ranks = 1);

// The sweep report with one column per axis and the derived columns (rods_mass_kg,
// coil_resistance_ohm, first_resonance_Hz, bandwidth_Hz, and per point coil_copper_loss_W:
// I_rms^2 R(T) of the point's drive); table "designs" has one row per design.
Report design_sweep_report(const Model& base, const SweepRequest& req,
                           const DesignSweepResult& res);

}  // namespace gmasim
