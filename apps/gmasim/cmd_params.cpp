// gmasim params-vs-temperature (Fig. 18, 19) and gmasim thermal (eq. 21).
#include <fmt/format.h>

#include <memory>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/claims.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/io/io.hpp"
#include "request_options.hpp"

namespace gmasim::cli {
namespace {

using ParamsArgs = ExperimentArgs<ParamsVsTemperatureRequest>;

void print_thermal(const ThermalExpansionResult& t) {
  fmt::print(
      "  thermal expansion, eq. (21): {:.4f} um/degC  (paper: model {} um/degC, measured {} "
      "um/degC)\n",
      t.um_per_C, t.paper_model_um_per_C, t.paper_measured_um_per_C);
  fmt::print("    rods +{:.4f}, magnetizers +{:.4f}, output rod +{:.4f}, sleeve -{:.4f} um/degC\n",
             t.rod_um_per_C, t.magnetizer_um_per_C, t.output_rod_um_per_C, t.sleeve_um_per_C);
}

int run_params_cmd(ParamsArgs& a) {
  const Model model = load_model_args(a.model);
  a.options.apply();
  warn_temperatures(model, a.req.temperatures_C, "--temperatures");
  prepare_output_dir(a.out, {"params", "thermal"}, model_inputs(a.model));
  const auto res = run_params_vs_temperature(model, a.req);
  auto files = write_report(a.out, "params", params_report(model, a.req, res));
  const auto th = thermal_expansion_coefficient(model);
  const auto thf = write_report(a.out, "thermal", thermal_report(model, th));
  files.insert(files.end(), thf.begin(), thf.end());

  fmt::print("gmasim params-vs-temperature  model: {}\n", model_label(a.model));
  fmt::print(
      "  Fig. 19 quantities at {} A peak-to-peak, {} Hz (means and peaks over the last "
      "period); changes vs {} degC\n",
      a.req.current_pp_A, a.req.frequency_Hz, a.req.temperatures_C.front());
  fmt::print(
      "  {:>6} {:>5} {:>8} {:>10} {:>10} {:>10} {:>8} {:>7} | {:>7} {:>7} {:>7} {:>7} {:>7}\n",
      "T degC", "rod", "mu_r", "rho uOhm m", "M_pk kA/m", "Ms^T kA/m", "E_G GPa", "E_t GPa", "dmu%",
      "drho%", "dM%", "dE_G%", "dE_t%");
  for (const auto& w : res.rows)
    fmt::print(
        "  {:6.1f} {:>5} {:8.3f} {:10.4f} {:10.2f} {:10.2f} {:8.3f} {:7.2f} | {:+7.1f} "
        "{:+7.1f} {:+7.1f} {:+7.1f} {:+7.1f}\n",
        w.temperature_C, w.rod, w.mu_r_mean, w.rho_ohm_m * 1e6, w.M_peak_A_per_m * 1e-3,
        w.MsT_A_per_m * 1e-3, w.E_G_mean_GPa, w.E_t_GPa, w.mu_r_change_pct, w.rho_change_pct,
        w.M_peak_change_pct, w.E_G_change_pct, w.E_t_change_pct);
  const ClaimSpec* c = builtin_claims().find("retention_150C_8A");  // data/claims.toml
  fmt::print(
      "\n  Fig. 18: stroke retention vs {} degC{}\n", a.req.temperatures_C.front(),
      c ? fmt::format(" (paper: ~{:g} % at {:g} degC)", c->paper, c->condition.temperature_C) : "");
  fmt::print("  {:>7} {:>6} {:>10} {:>10} {:>11} {:>9}\n", "I_pp A", "T degC", "stroke um",
             "hyst um", "stroke %", "hyst %");
  for (const auto& w : res.retention)
    fmt::print("  {:7.2f} {:6.1f} {:10.3f} {:10.3f} {:11.1f} {:9.1f}\n", w.current_pp_A,
               w.temperature_C, w.stroke_um, w.hysteresis_um, w.stroke_retention_pct,
               w.hysteresis_retention_pct);
  fmt::print("\n");
  print_thermal(th);
  if (a.plot) files.push_back(render_plot("params", a.out));
  fmt::print("  wrote {}\n", fmt::join(files, ", "));
  return 0;
}

}  // namespace

Runner add_params(CLI::App& app) {
  return add_experiment<ParamsArgs>(
      app,
      {"params-vs-temperature",
       "mu_G, rho_G, M_G, E_G and E_t against temperature (Fig. 19), stroke retention (Fig. 18) "
       "and the thermal expansion coefficient (eq. 21). Writes params*.csv, params.json, "
       "thermal.csv, thermal.json",
       "out/params", "Also draw <out>/params.png and .svg (matplotlib)", false},
      [](CLI::App*, ParamsArgs&) {}, run_params_cmd);
}

Runner add_thermal(CLI::App& app) {
  auto model = std::make_shared<ModelArgs>();
  auto out = std::make_shared<std::string>("out/thermal");
  auto* sub = app.add_subcommand(
      "thermal",
      fmt::format("Thermal expansion coefficient of the stack, eq. (21), against the paper's "
                  "{:g} (model) and {:g} (measured) um/degC. Writes thermal.csv, thermal.json",
                  builtin_paper_value("thermal_model"), builtin_paper_value("thermal_measured")));
  add_model_options(sub, *model);
  sub->add_option("--out", *out, "Output directory")->capture_default_str();
  return [=]() -> int {
    if (!sub->parsed()) return -1;
    const Model m = load_model_args(*model);
    prepare_output_dir(*out, {"thermal"}, model_inputs(*model));
    const auto th = thermal_expansion_coefficient(m);
    const auto files = write_report(*out, "thermal", thermal_report(m, th));
    fmt::print("gmasim thermal  model: {}\n", model_label(*model));
    print_thermal(th);
    fmt::print("  wrote {}\n", fmt::join(files, ", "));
    return 0;
  };
}

}  // namespace gmasim::cli
