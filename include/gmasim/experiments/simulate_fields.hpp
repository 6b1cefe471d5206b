// The options of a time-domain run as the user gives them (`gmasim simulate`, Python's
// gmasim.simulate) and their table (gmasim/experiments/request_table.hpp): the CLI options and
// the Python keyword arguments with their defaults are generated from it, the defaults typed
// once, here. The CLI (apps/gmasim/cmd_simulate.cpp) and Python (python/src/module.cpp) turn
// them into SimulationSettings and a Waveform; simulate() checks them there with its own
// messages, which these rules mirror (tests/test_request_tables.cpp).
// Their own options: the CLI's --temperature (a list; its default temperature_C), --waveform,
// --quantity, --freeze, --ambient; Python's waveform, current_A, freeze, quantities, ambient_C.
#pragma once

#include <string>
#include <tuple>

#include "gmasim/experiments/request_table.hpp"
#include "gmasim/experiments/shared_rows.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {

struct SimulateOptions {
  double temperature_C = 20.0;
  double current_pp_A = 8.0, frequency_Hz = 10.0, periods = 3.0, current_min_A = -3.0;
  double dt_s = 0.0;
  int record_every = 1;
  std::string kind = "sine";
  double level_A = 0.0, step_to_A = 0.0, step_time_s = 0.0;               // dc, step
  double f0_Hz = 1.0, f1_Hz = 1000.0, amplitude_A = 1.0, offset_A = 0.0;  // chirp
  double duration_s = 0.0;
  double metrics_window_s = 0.0;
  bool self_heating = false;
  double thermal_step_s = 0.0;
};

namespace fields {

// The order is Python's (its positional arguments as before); the CLI lists them so.
template <>
struct RequestFields<SimulateOptions> {
  using R = SimulateOptions;
  static constexpr std::string_view experiment = "simulate";
  static constexpr unsigned kCliPy = Cli | Python;
  static constexpr auto rows = std::tuple{
      field<R>("temperature_C", "degC", finite(), "", "", Python, GMASIM_REF(R, temperature_C)),
      field<R>("current_pp_A", "A", finite(), "--current-pp",
               "Biased sine: current peak-to-peak [A]", kCliPy, GMASIM_REF(R, current_pp_A)),
      field<R>("frequency_Hz", "Hz", positive(), "--frequency", "Biased sine: frequency [Hz]",
               kCliPy, GMASIM_REF(R, frequency_Hz)),
      periods_row<R>("Biased sine: number of periods to run [-]; metrics use the last", kCliPy),
      field<R>("current_min_A", "A", finite(), "--current-min",
               "Biased sine: current minimum [A] (paper: -3 A)", kCliPy,
               GMASIM_REF(R, current_min_A)),
      dt_row<R>("Time step [s]; 0 = automatic rule (T/2000, at most 10 us)", kCliPy),
      field<R>("record_every", "-", in(1.0, 2e9), "--record-every",
               "Record every N-th step [-]; not given, a run over 10000 rows writes one row in "
               "ceil(rows/10000) to timeseries.csv (the metrics use every step)",
               kCliPy, GMASIM_REF(R, record_every)),
      field<R>("kind", "-", any(), "--waveform-kind",
               "Current waveform: sine (biased, Fig. 11), dc, step, chirp", kCliPy,
               GMASIM_REF(R, kind)),
      field<R>("level_A", "A", finite(), "--level", "DC level, or step initial level [A]", Cli,
               GMASIM_REF(R, level_A)),
      field<R>("step_to_A", "A", finite(), "--step-to", "Step: level after the step [A]", Cli,
               GMASIM_REF(R, step_to_A)),
      field<R>("step_time_s", "s", finite(), "--step-time",
               "Step: time of the step, inside the run (0 < t < --duration) [s]", Cli,
               GMASIM_REF(R, step_time_s)),
      field<R>("f0_Hz", "Hz", positive(), "--f0", "Chirp: start frequency [Hz]", Cli,
               GMASIM_REF(R, f0_Hz)),
      field<R>("f1_Hz", "Hz", positive(), "--f1", "Chirp: end frequency [Hz]", Cli,
               GMASIM_REF(R, f1_Hz)),
      field<R>("amplitude_A", "A", finite(), "--amplitude", "Chirp: current amplitude [A]", Cli,
               GMASIM_REF(R, amplitude_A)),
      field<R>("offset_A", "A", finite(), "--offset", "Chirp: current offset [A]", Cli,
               GMASIM_REF(R, offset_A)),
      field<R>("duration_s", "s", nonnegative(), "--duration",
               "Run length for dc/step/chirp/CSV waveforms [s] (CSV: default its last time)",
               kCliPy, GMASIM_REF(R, duration_s)),
      field<R>("metrics_window_s", "s", nonnegative(), "--metrics-window",
               "Not a biased sine: the metrics over the run's last S seconds [s]; 0 = a CSV's "
               "declared period (# period_s = P), else the whole run",
               kCliPy, GMASIM_REF(R, metrics_window_s)),
      field<R>("self_heating", "-", any(), "--self-heating",
               "Let the actuator heat itself: coil copper loss and rod eddy/hysteresis losses "
               "drive the [thermal_network] (coil, rods, housing, ambient); the rods' "
               "temperature updates the model every thermal step. Writes self_heating.csv",
               kCliPy, GMASIM_REF(R, self_heating)),
      field<R>("thermal_step_s", "s", nonnegative(), "--thermal-step",
               "Self-heating: thermal step [s]; 0 = whole periods spanning >= 0.1 s", kCliPy,
               GMASIM_REF(R, thermal_step_s)),
  };
};

}  // namespace fields
}  // namespace gmasim
