// gmasim sweep: temperature x current x frequency grid (Fig. 12-14), points in parallel.
#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/io/io.hpp"
#include "request_options.hpp"

namespace gmasim::cli {
namespace {

using SweepArgs = ExperimentArgs<SweepRequest>;

int run_sweep_cmd(SweepArgs& a) {
  const Model model = load_model_args(a.model);
  a.options.apply();
  warn_temperatures(model, a.req.temperatures_C, "--temperatures");
  warn_temperatures(model, {a.req.reference_temperature_C}, "--reference-temperature");
  prepare_output_dir(a.out, {"sweep"}, model_inputs(a.model));
  const SweepResult res = run_sweep(model, a.req, stderr_progress("sweep", a.progress));
  auto files = write_report(a.out, "sweep", sweep_report(model, a.req, res));

  fmt::print("gmasim sweep  model: {}\n", model_label(a.model));
  fmt::print(
      "  {} points ({} simulations) on {} threads in {:.2f} s; metrics over the last of {} "
      "periods; changes vs {} degC\n",
      res.points.size(), res.simulations, res.threads, res.wall_time_s, a.req.periods,
      a.req.reference_temperature_C);
  fmt::print("  {:>6} {:>6} {:>8} {:>10} {:>10} {:>8} {:>9} {:>9} {:>9}\n", "T degC", "I_pp A",
             "f Hz", "stroke um", "hyst um", "B_pp T", "dstroke%", "dhyst%", "dB_pp%");
  int diverged = 0;
  for (const auto& p : res.points) {
    if (p.diverged) {
      ++diverged;
      fmt::print("  {:6.1f} {:6.2f} {:8.2f}  diverged: {}\n", p.temperature_C, p.current_pp_A,
                 p.frequency_Hz, p.error);
      continue;
    }
    fmt::print("  {:6.1f} {:6.2f} {:8.2f} {:10.3f} {:10.3f} {:8.4f} {:+9.2f} {:+9.2f} {:+9.2f}\n",
               p.temperature_C, p.current_pp_A, p.frequency_Hz, p.metrics.stroke_um,
               p.metrics.hysteresis_um, p.metrics.B_pp_T, p.stroke_change_pct,
               p.hysteresis_change_pct, p.B_pp_change_pct);
  }
  if (a.plot) files.push_back(render_plot("sweep", a.out));
  fmt::print("  wrote {}\n", fmt::join(files, ", "));
  if (diverged > 0) {
    for (const auto& p : res.points)
      if (p.diverged) {  // the first one's diagnosis (time, rod, quantity) on stderr too
        print_error(fmt::format(
            "{} of {} points diverged (recorded in the output); first at {:g} degC, {:g} A, "
            "{:g} Hz: {}",
            diverged, res.points.size(), p.temperature_C, p.current_pp_A, p.frequency_Hz, p.error));
        break;
      }
    return 3;
  }
  return 0;
}

}  // namespace

Runner add_sweep(CLI::App& app) {
  return add_experiment<SweepArgs>(
      app,
      {"sweep",
       "Grid over temperature x current peak-to-peak x frequency (Fig. 12-14): stroke, "
       "hysteresis, B peak-to-peak and their change vs a reference temperature; points run in "
       "parallel. Writes sweep.csv and sweep.json",
       "out/sweep", "Also draw <out>/sweep.png and .svg (matplotlib)"},
      [](CLI::App*, SweepArgs&) {}, run_sweep_cmd);
}

}  // namespace gmasim::cli
