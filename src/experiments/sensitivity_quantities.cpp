// The metric quantities of `gmasim sensitivity` (gmasim/experiments/sensitivity.hpp): scalars a
// user cares about beside the paper's claims, each read from a simulate run at one operating point
// (the sweep's settings: a biased sine from -3 A, 3 periods, the last measured) with the
// energy ledgers booked (gmasim/model/energy.hpp). A new scalar is one row; rows at the same
// operating point share one run.
#include "gmasim/experiments/sensitivity.hpp"

namespace gmasim {

std::vector<MetricQuantity> builtin_metric_quantities() {
  // name, unit, field, temperature_C, current_pp_A, frequency_Hz, relative scale, description
  return {
      {"stroke_um@20C_8A_10Hz", "um", [](const Result& r) { return r.metrics.stroke_um; }, 20.0,
       8.0, 10.0, 0.05, "stroke (peak-to-peak of y) at the paper's operating point, 20 degC"},
      {"hysteresis_um@20C_8A_10Hz", "um", [](const Result& r) { return r.metrics.hysteresis_um; },
       20.0, 8.0, 10.0, 0.05,
       "hysteresis width (max |y_rising - y_falling| at equal current), 20 degC"},
      {"B_pp_T@20C_8A_10Hz", "T", [](const Result& r) { return r.metrics.B_pp_T; }, 20.0, 8.0, 10.0,
       0.05, "flux density B peak to peak seen by the induction coil, 20 degC"},
      {"P_hysteresis_W@20C_8A_10Hz", "W",
       [](const Result& r) { return r.energy.hysteresis_J / r.energy.duration_s; }, 20.0, 8.0, 10.0,
       0.05, "the rods' hysteresis loss (energy ledger), mean over the last period"},
      {"P_eddy_W@20C_8A_10Hz", "W",
       [](const Result& r) { return r.energy.eddy_J / r.energy.duration_s; }, 20.0, 8.0, 10.0, 0.05,
       "the rods' eddy-current loss (energy ledger), mean over the last period"},
      {"P_eddy_W@20C_8A_200Hz", "W",
       [](const Result& r) { return r.energy.eddy_J / r.energy.duration_s; }, 20.0, 8.0, 200.0,
       0.05, "the rods' eddy-current loss (energy ledger) at 200 Hz"},
      {"P_damping_W@20C_8A_200Hz", "W",
       [](const Result& r) { return r.energy.damping_J / r.energy.duration_s; }, 20.0, 8.0, 200.0,
       0.05, "the rods' mechanical damping loss (energy ledger) at 200 Hz"},
  };
}

}  // namespace gmasim
