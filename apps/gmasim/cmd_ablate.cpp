// gmasim ablate: freeze one temperature law at 20 degC at a time (Fig. 20).
#include <fmt/format.h>

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

using AblateArgs = ExperimentArgs<AblateRequest>;

int run_ablate_cmd(AblateArgs& a) {
  const Model model = load_model_args(a.model);
  a.options.apply();
  warn_temperatures(model, {a.req.temperature_C}, "--temperature");
  prepare_output_dir(a.out, {"ablate"}, model_inputs(a.model));
  const AblateResult res = run_ablate(model, a.req);
  auto files = write_report(a.out, "ablate", ablate_report(model, a.req, res));

  fmt::print("gmasim ablate  model: {}\n", model_label(a.model));
  fmt::print(
      "  {} degC, {} A peak-to-peak from {} A; each law frozen at {} degC in turn; error = RMS "
      "of y_frozen - y_full over the last period\n",
      a.req.temperature_C, a.req.current_pp_A, a.req.current_min_A, model.T_ref_C);
  for (std::size_t fi = 0; fi < a.req.frequencies_Hz.size(); ++fi) {
    const auto& full = res.full[fi];
    fmt::print("\n  {} Hz: full model stroke {:.3f} um, hysteresis {:.3f} um\n",
               a.req.frequencies_Hz[fi], full.stroke_um, full.hysteresis_um);
    fmt::print("  {:>9} {:>11} {:>11} {:>9} {:>10} {:>10}\n", "law", "e_rms um", "e_peak um",
               "% stroke", "dstroke %", "dhyst %");
    for (const auto& row : res.rows) {
      if (row.frequency_Hz != a.req.frequencies_Hz[fi]) continue;
      if (row.diverged) {
        fmt::print("  {:>9}  diverged: {}\n", row.law, row.error);
        continue;
      }
      fmt::print("  {:>9} {:11.4f} {:11.4f} {:9.3f} {:+10.2f} {:+10.2f}\n", row.law,
                 row.error_rms_um, row.error_peak_um, row.error_pct_of_stroke,
                 row.stroke_change_pct, row.hysteresis_change_pct);
    }
  }
  if (a.plot) files.push_back(render_plot("ablate", a.out));
  fmt::print("\n  wrote {}\n", fmt::join(files, ", "));
  return 0;
}

}  // namespace

Runner add_ablate(CLI::App& app) {
  return add_experiment<AblateArgs>(
      app,
      {"ablate",
       fmt::format("Freeze the temperature dependence of each law ({}) at 20 degC one at a time, "
                   "then all; deviation from the full model (Fig. 20). Writes ablate.csv, "
                   "ablate.json",
                   freeze_name_list()),
       "out/ablate", "Also draw <out>/ablate.png and .svg (matplotlib)", false},
      [](CLI::App*, AblateArgs&) {}, run_ablate_cmd);
}

}  // namespace gmasim::cli
