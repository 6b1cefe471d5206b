// gmasim model show / params / save / check.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiments.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/parameters.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim::cli {
namespace {

// The two temperature ranges of a model (issue 19, item 8): where its laws can be computed
// (outside: refused) and where it was validated (outside: a warning).
std::string ranges_text(const Model& m) {
  const auto c = computable_range(m);
  return fmt::format(
      "computable {} (outside: refused); validated {} (validity.validated_min_C/max_C; outside: "
      "a warning)",
      c ? range_text(*c) : std::string("nowhere (not even at reference.T_ref_C)"),
      range_text(validated_range(m)));
}

// The coil's incremental inductance at T_ref, at 0 A and at the FRF's default bias of 1 A (issue
// 39 item 1: reported, not used by the step).
std::string inductance_text(const Model& m) {
  try {
    const CoilInductance a = coil_inductance(m, m.T_ref_C, 0.0);
    const CoilInductance b = coil_inductance(m, m.T_ref_C, 1.0);
    return fmt::format(
        "coil: incremental inductance {:.4g} mH at 0 A, {:.4g} mH at 1 A (dPsi/dI on the minor "
        "loop at the bias, {} degC; reported, not used by the step)",
        1e3 * a.inductance_H, 1e3 * b.inductance_H, m.T_ref_C);
  } catch (const DivergenceError& e) {
    return fmt::format("coil: incremental inductance not computed ({})", e.what());
  }
}

int run_show(const ModelArgs& a, bool doc) {
  const ModelSpec spec = load_model_spec_args(a);
  const Model m = compile(spec);  // show only valid models
  print_model_warnings(m);
  fmt::print("# {}\n", model_label(a));
  fmt::print("# temperatures: {}\n", ranges_text(m));
  fmt::print("# {}\n", inductance_text(m));
  fmt::print("{:<48} {:>14}  {:<10} {}\n", "parameter", "value", "unit",
             doc ? "meaning" : "provenance");
  for (const auto& row : describe_model(m.spec))  // with the derived quantities
    fmt::print("{:<48} {:>14}  {:<10} {}\n", row.name, row.value, row.unit,
               doc ? row.doc : row.provenance);
  return 0;
}

// The parameter table itself (gmasim/model/parameters.hpp), as text or as docs/parameters.md.
int run_params(bool markdown) {
  if (markdown) {
    fmt::print("{}", parameters_markdown());
    return 0;
  }
  fmt::print("{:<54} {:<9} {:<30} {:<9} {}\n", "key", "unit", "rule", "default", "meaning");
  for (const auto& g : parameter_groups())
    for (const auto& p : parameter_table())
      if (p.group == g.group)
        fmt::print("{:<54} {:<9} {:<30} {:<9} {} [{}]\n", fmt::format("{}.{}", g.path, p.key),
                   p.unit, row_rule_text(p),
                   p.default_value ? fmt::format("{:g}", *p.default_value) : "-", p.doc,
                   p.lands_in);
  for (const auto& o : option_table()) {
    std::string words;
    for (const auto& c : o.choices) words += (words.empty() ? "" : "|") + std::string(c.word);
    fmt::print("{:<54} {:<9} {:<30} {:<9} {} [{}]\n", fmt::format("options.{}", o.key), "option",
               words, "-", o.doc, o.lands_in);
  }
  return 0;
}

int run_check(ModelArgs args, const std::string& file, bool dt_table) {
  if (!file.empty()) {
    if (!args.path.empty() && args.path != file)
      throw InputError(
          fmt::format("model check: the file '{}' and --model '{}' name two models; "
                      "give one",
                      file, args.path));
    args.path = file;
  }
  const std::string path = model_label(args);
  if (dt_table) {  // docs/model.md, "Time step" (its test compares the page with this output)
    fmt::print("{}", time_step_table_markdown(load_model_args(args)));
    return 0;
  }
  try {
    const Model m = load_model_args(args);
    (void)make_conditions(m, m.T_ref_C);
    fmt::print("{}: OK ({} parameters, {} rods, {} circuit nodes, {} branches)\n", path,
               m.spec.params.size(), m.rods.size(), m.circuit.node_count(),
               m.circuit.branch_count());
    fmt::print("temperatures: {}\n", ranges_text(m));
    for (const auto& w : model_warnings(m)) fmt::print("warning: {}\n", w);
    const TemperatureRange v = validated_range(m);
    if (const auto c = computable_range(m); c && (v.min_C < c->min_C || v.max_C > c->max_C))
      fmt::print("warning: the validated range {} reaches beyond the computable range {}\n",
                 range_text(v), range_text(*c));
    const MagneticStateCheck k = check_magnetic_state(m);
    fmt::print(
        "magnetic state over {} runs (20/70/150 degC x 6/12 A x 10/400 Hz), "
        "options.magnetic_state "
        "= {}:\n"
        "  max |B| of the induction coil          {:.4f} T\n"
        "  max |phi/A| of a rod                   {:.4f} T   ({})\n"
        "  max |phi/A - mu0 (H + M)| of a rod     {:.3g} T   ({:.3g} of mu0 (|H| + M_s^T); "
        "{})\n",
        k.runs, option_word(*find_option_def("magnetic_state"), m.options), k.max_B_sensor_T,
        k.max_B_rod_T, k.where_B_rod, k.max_inconsistency_T, k.max_inconsistency_rel,
        k.where_inconsistency);
    // docs/model.md, "Energy ledgers": the worse of the magnetic and mechanical ledgers' relative
    // residuals over the last period of each run (the printed reading cannot close: its rods'
    // branch flux is not A mu0 (H + M)).
    fmt::print("energy balance residual: {:.3g}   ({})\n", k.energy_residual_rel, k.where_energy);
    fmt::print(
        "  coupling: the mechanical input the one-way coupling does not draw from the coil is at "
        "most {:.2f} % of the magnetic input\n",
        100.0 * k.max_coupling_fraction);
    if (!k.divergence.empty()) {
      fmt::print(stderr, "diverged: {}\n", k.divergence);
      return 3;
    }
    return 0;
  } catch (const InputError& e) {
    fmt::print(stderr, "{}: INVALID\n{}\n", path, e.what());
    return 2;
  }
}

// The shipped models (shipped_models_dir()): each file's bare name, [meta] name and description.
int run_list() {
  namespace fs = std::filesystem;
  const std::string dir = shipped_models_dir();
  if (dir.empty())
    throw InputError(
        "no shipped models directory: neither $GMASIM_MODELS_DIR nor "
        "<prefix>/share/gmasim/models beside this executable exists");
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".toml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  fmt::print("# shipped models in {} (use the name with --model, e.g. --model {})\n", dir,
             files.empty() ? "mdma_printed" : files.front().stem().string());
  std::vector<std::array<std::string, 3>> rows = {{"name", "meta.name", "meta.description"}};
  for (const auto& f : files) {
    const ModelSpec spec = load_model_spec(f.string());
    auto meta = [&](const char* key) {
      const auto it = spec.meta.find(key);
      return it == spec.meta.end() ? std::string() : it->second;
    };
    rows.push_back({f.stem().string(), meta("meta.name"), meta("meta.description")});
  }
  std::size_t w0 = 0, w1 = 0;
  for (const auto& r : rows) {
    w0 = std::max(w0, r[0].size());
    w1 = std::max(w1, r[1].size());
  }
  for (const auto& r : rows) fmt::print("{:<{}}  {:<{}}  {}\n", r[0], w0, r[1], w1, r[2]);
  fmt::print("(no --model: the built-in MDMA model, models/mdma.toml compiled in)\n");
  return 0;
}

}  // namespace

Runner add_model(CLI::App& app) {
  auto* sub = app.add_subcommand("model", "Inspect and validate model files");
  sub->require_subcommand(1);
  auto show_model = std::make_shared<ModelArgs>();
  auto save_model_args = std::make_shared<ModelArgs>();
  auto save_out = std::make_shared<std::string>();
  auto check_path = std::make_shared<std::string>();
  auto show_doc = std::make_shared<bool>(false);
  auto params_markdown = std::make_shared<bool>(false);
  auto* show =
      sub->add_subcommand("show", "List every parameter with its value, unit and provenance");
  add_model_options(show, *show_model);
  show->add_flag("--doc", *show_doc,
                 "Show each parameter's meaning (the parameter table) instead of its provenance");
  auto* params = sub->add_subcommand(
      "params",
      "The parameter table: every key a model file may hold, its unit, rule, meaning, default "
      "and the Model field it lands in (docs/parameters.md)");
  params->add_flag("--markdown", *params_markdown, "Print docs/parameters.md (Markdown)");
  auto* save = sub->add_subcommand(
      "save",
      "Write a model file with --set changes applied (each changed value keeps its line and "
      "gets a 'set:' provenance comment naming the old value)");
  add_model_options(save, *save_model_args);
  save->add_option("--out", *save_out, "Model file to write (TOML)")->required();
  auto check_model = std::make_shared<ModelArgs>();
  auto* check = sub->add_subcommand(
      "check",
      "Validate a model (default: the built-in one) and explain each problem; run it over "
      "20/70/150 degC x 6/12 A x 10/400 Hz: flux densities, consistency and the energy ledgers");
  check->add_option("file", *check_path, "Model file (TOML); same as --model")
      ->transform(model_path_transform());
  add_model_options(check, *check_model);
  auto* list = sub->add_subcommand(
      "list", "List the shipped model files by the name --model takes, with their [meta]");
  auto dt_table = std::make_shared<bool>(false);
  check->add_flag("--dt-table", *dt_table,
                  "Print only the time-step table of docs/model.md (convergence as dt halves, "
                  "observed order, the eddy field's ringing threshold), as Markdown");
  return [=]() -> int {
    if (show->parsed()) return run_show(*show_model, *show_doc);
    if (list->parsed()) return run_list();
    if (params->parsed()) return run_params(*params_markdown);
    if (save->parsed()) {
      const ModelSpec spec = load_model_spec_args(*save_model_args);
      require_outputs_distinct(model_inputs(*save_model_args), {{*save_out, "--out"}});
      save_model(spec, *save_out, "gmasim model save --set");
      fmt::print("wrote {} ({} with {} change{})\n", *save_out, model_label(save_model_args->path),
                 save_model_args->sets.size(), save_model_args->sets.size() == 1 ? "" : "s");
      return 0;
    }
    if (check->parsed()) return run_check(*check_model, *check_path, *dt_table);
    return -1;
  };
}

}  // namespace gmasim::cli
