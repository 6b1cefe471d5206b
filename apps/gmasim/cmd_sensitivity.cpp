// gmasim sensitivity: d(claim) / d ln(parameter) of every claim and metric quantity at two
// step sizes, flags, identifiability (docs/experiments.md, "Sensitivity").
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/experiment_fields.hpp"
#include "gmasim/experiments/sensitivity.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "request_options.hpp"

namespace gmasim::cli {
namespace {

namespace fs = std::filesystem;

struct SensitivityArgs {
  ModelArgs model;
  std::vector<std::string> params, quantities;
  std::string fit, claims, out, json, csv;
  SensitivityRequest req;
  RequestOptions<SensitivitySettings> options;
  bool plot = false, progress = false;
};

// "name" or "name:SCALE" (the absolute step's scale, in the parameter's unit).
SensitivityParameter parse_param(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) return {text, 0.0};
  if (text.find(':') != colon)
    throw InputError(fmt::format(
        "--param {}: expected NAME or NAME:SCALE (one ':', the absolute step's scale in the "
        "parameter's unit), e.g. --param material.Ms_A_per_m:1e3; a fit's bounds go in --fit "
        "(name:lower:upper)",
        clip_error_message(text)));
  const std::string num = text.substr(colon + 1);
  char* end = nullptr;
  const double s = std::strtod(num.c_str(), &end);
  if (num.empty() || end != num.c_str() + num.size() || !std::isfinite(s) || !(s > 0.0))
    throw InputError(fmt::format("--param {}: the scale after ':' must be a finite number > 0",
                                 clip_error_message(text)));
  return {text.substr(0, colon), s};
}

std::vector<SensitivityParameter> parameters_of(const SensitivityArgs& a, const ModelSpec& spec) {
  std::vector<SensitivityParameter> out;
  if (!a.fit.empty()) {
    // The fit spec's free parameters; an absolute step at 0 takes the width of its bounds.
    for (const FitParameter& fp : load_fit_spec(a.fit).parameters) {
      const double v = spec.get(fp.name);
      out.push_back({fp.name, v == 0.0 ? fp.upper - fp.lower : 0.0});
    }
  }
  for (const auto& p : a.params) {
    if (p == "all") {
      for (auto& q : model_parameters(spec)) out.push_back(std::move(q));
    } else {
      out.push_back(parse_param(p));
    }
  }
  if (out.empty())
    throw InputError("no parameter: give --param NAME (repeatable, or 'all') or --fit FILE");
  return out;
}

void check_flags(const SensitivityArgs& a) {
  const SensitivityRequest& r = a.req;
  auto in = [](double v, double lo, double hi, const char* flag) {
    if (!std::isfinite(v) || !(v > lo) || !(v < hi))
      throw InputError(fmt::format("{} {}: must be in ({:g}, {:g})", flag, v, lo, hi));
  };
  in(r.step_large, 0.0, 0.5, "--step-large");
  in(r.step_small, 0.0, 0.5, "--step-small");
  if (!(r.step_small < r.step_large))
    throw InputError(fmt::format("--step-small {:g}: must be below --step-large {:g}", r.step_small,
                                 r.step_large));
  in(r.agreement, 0.0, 1.0 + 1e-12, "--agreement");
  in(r.near_null_ratio, 0.0, 1.0, "--near-null");
  if (!std::isfinite(r.floor_fraction) || r.floor_fraction < 0.0 || r.floor_fraction >= 1.0)
    throw InputError(fmt::format("--floor {}: must be in [0, 1)", r.floor_fraction));
  if (r.threads < 0 || r.threads > 4096)
    throw InputError(fmt::format("--threads {}: must be in [0, 4096] (0: all cores)", r.threads));
  if (a.json == "-" && a.csv == "-")
    throw InputError("--json - and --csv -: only one of them can go to standard output");
  if (a.plot && a.out.empty())
    throw InputError(
        "--plot draws into --out DIR: give --out (with --json/--csv alone no "
        "directory is written)");
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
}

// No output may overwrite an input (the model, the fit spec, the claims file).
void refuse_overwrite(const SensitivityArgs& a, const std::vector<std::string>& outputs) {
  for (const std::string& in : {a.model.path, a.fit, a.claims}) {
    if (in.empty()) continue;
    for (const auto& o : outputs)
      if (o != "-" && same_file(in, o))
        throw InputError(fmt::format("output {} would overwrite the input file {}", o, in));
  }
}

void print_quantities(const SensitivityResult& r, std::FILE* f) {
  fmt::print(f, "\n  {:<28} {:>11} {:<4}  largest |d q / d ln p| (per tolerance)\n", "quantity",
             "value", "unit");
  for (std::size_t i = 0; i < r.quantities.size(); ++i) {
    const QuantityInfo& q = r.quantities[i];
    std::vector<std::size_t> order(r.parameters.size());
    for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
    auto mag = [&](std::size_t j) {
      const double v = std::fabs(r.entries[i][j].scaled_large);
      return std::isfinite(v) ? v : -1.0;
    };
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t x, std::size_t y) { return mag(x) > mag(y); });
    std::string top;
    for (std::size_t k = 0; k < std::min<std::size_t>(3, order.size()); ++k) {
      const SensitivityEntry& e = r.entries[i][order[k]];
      if (!std::isfinite(e.scaled_large)) continue;
      top += fmt::format(
          "{}{} {:+.3g}{}{}", top.empty() ? "" : ", ", r.parameters[order[k]].name, e.scaled_large,
          std::isfinite(q.scale) ? fmt::format(" ({:+.2f})", e.scaled_large / q.scale) : "",
          e.flag == EntryFlag::Ok ? "" : " !");
    }
    fmt::print(f, "  {:<28} {:>11.5g} {:<4}  {}\n", q.name, q.value, q.unit, top);
  }
}

void print_identifiability(const SensitivityResult& r, std::FILE* f) {
  const Identifiability& id = r.identifiability;
  fmt::print(f,
             "\n  identifiability: {} quantities with a scale, {} parameters; rank {} (singular "
             "values above the near-null ratio), condition {:.3g}\n",
             id.quantities.size(), r.parameters.size(), id.rank, id.condition);
  int weak = 0;
  for (const auto& d : id.directions) weak += d.weak ? 1 : 0;
  fmt::print(f,
             "    {} weak directions (singular value < 1: a factor e along them moves the "
             "quantities by less than one tolerance)\n",
             weak);
  for (std::size_t k = 0; k < id.directions.size(); ++k) {
    const Direction& d = id.directions[k];
    const bool smallest = k + 3 >= id.directions.size();
    if (!d.near_null && !d.weak && !smallest) continue;
    fmt::print(f, "    {:<9} sigma {:.3g} ({:.2g} of the largest): {}\n",
               d.near_null ? "near-null" : (d.weak ? "weak" : "smallest"), d.singular_value,
               d.ratio, direction_text(d, r.parameters));
  }
  for (std::size_t j = 0; j < id.correlation.size(); ++j)
    for (std::size_t k = j + 1; k < id.correlation.size(); ++k)
      if (std::fabs(id.correlation[j][k]) > 0.9)
        fmt::print(f, "    correlation {} ~ {}: {:+.3f}\n", r.parameters[j].name,
                   r.parameters[k].name, id.correlation[j][k]);
}

void print_summary(const SensitivityArgs& a, const SensitivityResult& r, std::FILE* f) {
  fmt::print(f, "gmasim sensitivity  model: {}\n", model_label(a.model));
  fmt::print(f,
             "  {} parameters x {} quantities; central differences at h = {:g} and {:g} "
             "(agreement {:g} %); {} models, {} work items on {} threads in {:.1f} s\n",
             r.parameters.size(), r.quantities.size(), r.settings.step_large, r.settings.step_small,
             100 * r.settings.agreement, r.evaluations, r.runs, r.threads, r.wall_time_s);
  for (const auto& p : r.parameters)
    fmt::print(f, "    {:<44} {:>12.6g} {:<8} {}\n", p.name, p.value, p.unit,
               p.step == StepKind::Log ? "d/d ln p" : fmt::format("d/d p, step h x {:g}", p.scale));
  print_quantities(r, f);
  fmt::print(f,
             "  (q unit per unit ln p, or per unit p/scale; in brackets per tolerance; ! "
             "flagged)\n");
  const int flagged = r.flagged();
  fmt::print(f, "\n  flagged entries: {} of {}\n", flagged,
             r.quantities.size() * r.parameters.size());
  int shown = 0;
  for (std::size_t i = 0; i < r.quantities.size(); ++i)
    for (std::size_t j = 0; j < r.parameters.size(); ++j) {
      const SensitivityEntry& e = r.entries[i][j];
      if (e.flag == EntryFlag::Ok || ++shown > 12) continue;
      fmt::print(f, "    {} / {}: {}: {}\n", r.quantities[i].name, r.parameters[j].name,
                 entry_flag_name(e.flag), clip_error_message(e.message));
    }
  if (shown > 12) fmt::print(f, "    ... ({} more in sensitivity.json)\n", shown - 12);
  print_identifiability(r, f);
}

int run_sensitivity_cmd(SensitivityArgs& a) {
  check_flags(a);
  const ModelSpec spec = load_model_spec_args(a.model);
  const Model model = compile(spec);
  const ClaimsData claims = a.claims.empty() ? builtin_claims() : load_claims(a.claims);
  a.req.claims = &claims;
  a.req.parameters = parameters_of(a, spec);
  a.req.only = a.quantities;
  std::vector<std::string> outputs;
  std::vector<FileArg> output_args;  // the same files, by flag: no two flags may share one
  for (const auto& [o, flag] : {std::pair{a.json, "--json"}, std::pair{a.csv, "--csv"}})
    if (!o.empty() && o != "-") output_args.push_back({o, flag});
  for (const auto& o : {a.json, a.csv})
    if (!o.empty()) outputs.push_back(o);
  if (a.out.empty() && a.json.empty() && a.csv.empty()) a.out = "out/sensitivity";
  if (!a.out.empty())
    for (const char* name : {"sensitivity.csv", "sensitivity.json", "identifiability.json",
                             "sensitivity.png", "sensitivity.svg"}) {
      outputs.push_back((fs::path(a.out) / name).string());
      output_args.push_back({outputs.back(), "--out"});
    }
  refuse_overwrite(a, outputs);
  require_outputs_distinct({}, output_args, {});
  if (!a.out.empty()) ensure_output_dir(a.out);

  const SensitivityResult r =
      run_sensitivity(model, a.req, stderr_progress("sensitivity", a.progress));
  const std::string label = model_label(a.model);
  const std::string csv = sensitivity_csv(r), json = sensitivity_json(r, label);
  std::vector<std::string> files;
  if (!a.out.empty()) {
    const fs::path d(a.out);
    write_files_atomic({{(d / "sensitivity.csv").string(), csv},
                        {(d / "sensitivity.json").string(), json},
                        {(d / "identifiability.json").string(), identifiability_json(r, label)}});
    files = {(d / "sensitivity.csv").string(), (d / "sensitivity.json").string(),
             (d / "identifiability.json").string()};
  }
  const bool to_stdout = a.json == "-" || a.csv == "-";
  if (a.json == "-") fmt::print("{}", json);
  if (a.csv == "-") fmt::print("{}", csv);
  for (const auto& [path, text] : {std::pair{a.json, json}, std::pair{a.csv, csv}})
    if (!path.empty() && path != "-") {
      write_file_atomic(path, text);
      files.push_back(path);
    }
  if (a.plot) files.push_back(render_plot("sensitivity", a.out));
  std::FILE* f = to_stdout ? stderr : stdout;
  print_summary(a, r, f);
  if (!files.empty()) fmt::print(f, "\n  wrote {}\n", fmt::join(files, ", "));
  return 0;
}

void add_flags(CLI::App* sub, SensitivityArgs& a) {
  sub->add_option("--param", a.params,
                  "A parameter (dotted name, e.g. material.Ms_A_per_m); NAME:SCALE gives an "
                  "absolute step's scale [its unit]; 'all': every number of the model a user "
                  "would vary; repeatable");
  sub->add_option("--fit", a.fit,
                  "Take the free parameters of this fit spec (TOML [[parameter]] tables, or "
                  "inline name:lower:upper,...), e.g. calibration/consistent.toml");
  sub->add_option("--claim", a.quantities,
                  "Keep only these quantities: claim ids or metric names (repeatable); "
                  "default: every applicable claim and metric quantity");
  sub->add_option("--claims", a.claims,
                  "Claims file (the format of data/claims.toml) instead of the built-in claims");
  // --step-large ... --threads: the table of SensitivitySettings
  // (gmasim/experiments/experiment_fields.hpp).
  a.options.add(sub, a.req);
  sub->add_option("--out", a.out,
                  "Output directory (sensitivity.csv, sensitivity.json, identifiability.json); "
                  "default out/sensitivity unless --json or --csv is given");
  sub->add_option("--json", a.json, "Also write sensitivity.json here; '-': standard output");
  sub->add_option("--csv", a.csv, "Also write sensitivity.csv here; '-': standard output");
  sub->add_flag("--plot", a.plot, "Also draw <out>/sensitivity.png and .svg (matplotlib)");
  sub->add_flag("--progress", a.progress, "Progress on stderr even when it is not a terminal");
}

}  // namespace

Runner add_sensitivity(CLI::App& app) {
  auto a = std::make_shared<SensitivityArgs>();
  auto* sub = app.add_subcommand(
      "sensitivity",
      "d(claim)/d ln(parameter) of every claim and metric quantity, by central differences at "
      "two step sizes (flagged where they disagree), and identifiability (correlations, "
      "near-null directions). Writes sensitivity.csv, sensitivity.json, identifiability.json");
  add_model_options(sub, a->model);
  add_flags(sub, *a);
  return [a, sub]() -> int { return sub->parsed() ? run_sensitivity_cmd(*a) : -1; };
}

}  // namespace gmasim::cli
