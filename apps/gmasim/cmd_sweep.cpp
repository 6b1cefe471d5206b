// gmasim sweep: temperature x current x frequency grid (Fig. 12-14), points in parallel.
#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/io/io.hpp"

namespace gmasim::cli {
namespace {

struct SweepArgs {
  bool plot = false;  // --plot: draw the figure (gmasim.command_figures)
  ModelArgs model;
  std::string out = "out/sweep";
  std::string temperatures = "20:10:70", currents = "6,8,10,12", frequencies = "10";
  SweepRequest req;
  bool progress = false;
};

int run_sweep_cmd(SweepArgs& a) {
  const Model model = load_model_args(a.model);
  a.req.temperatures_C = parse_list(a.temperatures, "--temperatures", "degC");
  warn_temperatures(model, a.req.temperatures_C, "--temperatures");
  warn_temperatures(model, {a.req.reference_temperature_C}, "--reference-temperature");
  a.req.currents_pp_A = parse_list(a.currents, "--currents", "A");
  a.req.frequencies_Hz = parse_list(a.frequencies, "--frequencies", "Hz");
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
  auto a = std::make_shared<SweepArgs>();
  auto* sub = app.add_subcommand(
      "sweep",
      "Grid over temperature x current peak-to-peak x frequency (Fig. 12-14): stroke, "
      "hysteresis, B peak-to-peak and their change vs a reference temperature; points run in "
      "parallel. Writes sweep.csv and sweep.json");
  add_model_options(sub, a->model);
  sub->add_option("--temperatures", a->temperatures,
                  "Temperatures [degC]: list '20,30,40' or range start:step:stop")
      ->capture_default_str();
  sub->add_option("--currents", a->currents,
                  "Current peak-to-peak values [A] of the biased sine (Fig. 11); list or range")
      ->capture_default_str();
  sub->add_option("--frequencies", a->frequencies, "Excitation frequencies [Hz]; list or range")
      ->capture_default_str();
  sub->add_option("--reference-temperature", a->req.reference_temperature_C,
                  "Relative changes are against this temperature [degC] (run even if not in "
                  "the grid)")
      ->capture_default_str();
  sub->add_option("--current-min", a->req.current_min_A,
                  "Minimum of the biased sine [A] (paper: -3 A)")
      ->capture_default_str();
  sub->add_option("--periods", a->req.periods, "Periods per point [-]; metrics over the last one")
      ->capture_default_str();
  sub->add_option("--dt", a->req.dt_s, "Time step [s]; 0 = automatic rule (T/2000, at most 10 us)")
      ->capture_default_str();
  sub->add_option("--threads", a->req.threads, "Worker threads [-]; 0 = all cores")
      ->capture_default_str();
  sub->add_flag("--progress", a->progress, "Progress on stderr even when it is not a terminal");
  sub->add_flag("--plot", a->plot, "Also draw <out>/sweep.png and .svg (matplotlib)");
  sub->add_option("--out", a->out, "Output directory")->capture_default_str();
  return [a, sub]() -> int { return sub->parsed() ? run_sweep_cmd(*a) : -1; };
}

}  // namespace gmasim::cli
