// gmasim sweep: temperature x current x frequency grid (Fig. 12-14), points in parallel.
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/design_sweep.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/identify/design.hpp"
#include "gmasim/io/io.hpp"
#include "request_options.hpp"

namespace gmasim::cli {
namespace {

struct SweepArgs : ExperimentArgs<SweepRequest> {
  std::vector<std::string> grid;  // --grid KEY=v1,v2,... (repeatable)
  std::string mpi = "auto";       // --grid's designs over MPI ranks
};

// "KEY=v1,v2,..." or "KEY=start:step:stop".
GridAxis grid_axis(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw InputError(fmt::format(
        "--grid '{}': expected KEY=v1,v2,... or KEY=start:step:stop (a model key as `gmasim "
        "model show` lists it, e.g. --grid rod1.length_m=0.08,0.1)",
        clip_for_message(text)));
  const std::string key = text.substr(0, eq);
  return {key, parse_list(text.substr(eq + 1), "--grid " + key, "the key's unit")};
}

// The points of one sweep; with `loss`, each point's coil copper loss [W] too.
int print_points(const SweepResult& res, const std::vector<double>* loss) {
  fmt::print("  {:>6} {:>6} {:>8} {:>10} {:>10} {:>8} {:>9} {:>9} {:>9}{}\n", "T degC", "I_pp A",
             "f Hz", "stroke um", "hyst um", "B_pp T", "dstroke%", "dhyst%", "dB_pp%",
             loss ? fmt::format(" {:>8}", "P_Cu W") : "");
  int diverged = 0;
  for (std::size_t i = 0; i < res.points.size(); ++i) {
    const SweepPoint& p = res.points[i];
    if (p.diverged) {
      ++diverged;
      fmt::print("  {:6.1f} {:6.2f} {:8.2f}  diverged: {}\n", p.temperature_C, p.current_pp_A,
                 p.frequency_Hz, p.error);
      continue;
    }
    fmt::print("  {:6.1f} {:6.2f} {:8.2f} {:10.3f} {:10.3f} {:8.4f} {:+9.2f} {:+9.2f} {:+9.2f}{}\n",
               p.temperature_C, p.current_pp_A, p.frequency_Hz, p.metrics.stroke_um,
               p.metrics.hysteresis_um, p.metrics.B_pp_T, p.stroke_change_pct,
               p.hysteresis_change_pct, p.B_pp_change_pct,
               loss ? fmt::format(" {:8.2f}", (*loss)[i]) : "");
  }
  return diverged;
}

// The first diverged point's diagnosis on stderr (time, rod, quantity); exit status 3.
int report_divergence(const SweepResult& res, int diverged, const std::string& design) {
  for (const auto& p : res.points)
    if (p.diverged) {
      print_error(fmt::format(
          "{} of {} points{} diverged (recorded in the output); first at {:g} degC, {:g} A, "
          "{:g} Hz: {}",
          diverged, res.points.size(), design, p.temperature_C, p.current_pp_A, p.frequency_Hz,
          p.error));
      break;
    }
  return 3;
}

// The design study, its designs shared over the MPI ranks (rank 0 gathers them and writes).
int run_design_sweep_cmd(SweepArgs& a, Communicator& comm) {
  const bool root = comm.rank() == 0;
  const Model model = load_model_args(a.model);
  a.options.apply();
  if (root) {
    warn_temperatures(model, a.req.temperatures_C, "--temperatures");
    warn_temperatures(model, {a.req.reference_temperature_C}, "--reference-temperature");
    prepare_output_dir(a.out, {"sweep"}, model_inputs(a.model));
  }
  std::vector<GridAxis> axes;
  for (const auto& g : a.grid) axes.push_back(grid_axis(g));
  const DesignSweepResult res = run_design_sweep_ranks(
      model.spec, axes, a.req, comm, root ? stderr_progress("sweep", a.progress) : ProgressFn{});
  if (!root) return 0;
  auto files = write_report(a.out, "sweep", design_sweep_report(model, a.req, res));
  fmt::print("gmasim sweep  model: {}\n", model_label(a.model));
  fmt::print(
      "  {} designs x {} points on {} rank(s) in {:.2f} s; metrics over the last of {} periods; "
      "changes vs {} "
      "degC; small-signal markers at {} degC about the {:g} A bias\n",
      res.designs.size(), res.designs.empty() ? 0 : res.designs[0].sweep.points.size(), comm.size(),
      res.wall_time_s, a.req.periods, a.req.reference_temperature_C, a.req.reference_temperature_C,
      res.bias_A);
  int status = 0;
  for (const DesignPoint& d : res.designs) {
    std::string values;
    for (std::size_t k = 0; k < axes.size(); ++k)
      values += fmt::format("{}{}={:g}", k ? ", " : "", axes[k].key, d.values[k]);
    fmt::print(
        "\n  design {}: rods {:.4g} kg, coil {:.4g} ohm, first resonance {:.1f} Hz, -3 dB {:.1f} "
        "Hz\n",
        values, d.rods_mass_kg, d.coil_resistance_ohm, d.first_resonance_Hz, d.bandwidth_Hz);
    const int diverged = print_points(d.sweep, &d.copper_loss_W);
    if (diverged > 0) status = report_divergence(d.sweep, diverged, " of design " + values);
  }
  if (a.plot)
    print_warning(
        "--plot with --grid: the sweep figure draws one design; a design study's figure is not "
        "drawn -- sweep.csv holds every design's points beside its keys' values");
  fmt::print("  wrote {}\n", fmt::join(files, ", "));
  return status;
}

int run_sweep_cmd(SweepArgs& a) {
  if (!a.grid.empty())
    return run_on_ranks(a.mpi, "sweep --grid",
                        [&](Communicator& comm) { return run_design_sweep_cmd(a, comm); });
  if (launched_by_mpi() && env_int("OMPI_COMM_WORLD_SIZE", 1) > 1)
    throw InputError(
        "sweep: launched by mpirun: MPI ranks share the designs of --grid; a sweep without "
        "--grid runs on the cores of one machine (--threads)");
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
  const int diverged = print_points(res, nullptr);
  if (a.plot) files.push_back(render_plot("sweep", a.out));
  fmt::print("  wrote {}\n", fmt::join(files, ", "));
  return diverged > 0 ? report_divergence(res, diverged, "") : 0;
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
      [](CLI::App* sub, SweepArgs& a) {
        sub->add_option("--grid", a.grid,
                        "A design grid over a model key, KEY=v1,v2,... or KEY=start:step:stop "
                        "(repeatable: the keys' values are crossed; each design is the model "
                        "with those values, recompiled so that what they derive follows); adds "
                        "rods_mass_kg, coil_resistance_ohm, first_resonance_Hz, bandwidth_Hz and "
                        "coil_copper_loss_W columns and a 'designs' table");
      },
      run_sweep_cmd);
}

}  // namespace gmasim::cli
