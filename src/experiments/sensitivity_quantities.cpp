// The metric quantities of `gmasim sensitivity` (gmasim/sensitivity.hpp): scalars a user
// cares about beside the paper's claims, each one field of a simulate run's Metrics at one
// operating point (the sweep's settings: a biased sine from -3 A, 3 periods, the last
// measured).
//
// THE EXTENSION POINT. A new scalar of Metrics (e.g. the energy ledger's losses, issue 18
// item 1) becomes a sensitivity quantity with one row here:
//     {"P_hysteresis_W@20C_8A_10Hz", "W", &Metrics::P_hysteresis_W, 20, 8, 10, 0.05,
//      "hysteresis loss of the rods, mean over the last period"},
// Rows at the same operating point share one run.
#include "gmasim/sensitivity.hpp"

namespace gmasim {

std::vector<MetricQuantity> builtin_metric_quantities() {
  // name, unit, field, temperature_C, current_pp_A, frequency_Hz, relative scale, description
  return {
      {"stroke_um@20C_8A_10Hz", "um", &Metrics::stroke_um, 20.0, 8.0, 10.0, 0.05,
       "stroke (peak-to-peak of y) at the paper's operating point, 20 degC"},
      {"hysteresis_um@20C_8A_10Hz", "um", &Metrics::hysteresis_um, 20.0, 8.0, 10.0, 0.05,
       "hysteresis width (max |y_rising - y_falling| at equal current), 20 degC"},
      {"B_pp_T@20C_8A_10Hz", "T", &Metrics::B_pp_T, 20.0, 8.0, 10.0, 0.05,
       "flux density B peak to peak seen by the induction coil, 20 degC"},
  };
}

}  // namespace gmasim
