// Subcommands of the gmasim CLI. Each registers its options on a CLI11 subcommand and
// returns the function that runs it (exit code). The CLI holds no physics.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "gmasim/model.hpp"

namespace gmasim::cli {

using Runner = std::function<int()>;

Runner add_simulate(CLI::App& app);
Runner add_model(CLI::App& app);
Runner add_reproduce(CLI::App& app);
Runner add_identify(CLI::App& app);  // cmd_identify.cpp: identify, identify synthesize
Runner add_sweep(CLI::App& app);    // cmd_sweep.cpp
Runner add_frf(CLI::App& app);      // cmd_frf.cpp
Runner add_track(CLI::App& app);    // cmd_track.cpp
Runner add_ablate(CLI::App& app);   // cmd_ablate.cpp
Runner add_params(CLI::App& app);   // cmd_params.cpp: params-vs-temperature
Runner add_thermal(CLI::App& app);  // cmd_params.cpp: thermal
Runner add_compensate(CLI::App& app);  // cmd_compensate.cpp
Runner add_sensitivity(CLI::App& app);  // cmd_sensitivity.cpp

// --model FILE and --set name=value (repeatable), on every command that runs a model.
struct ModelArgs {
  std::string path;               // empty: the built-in MDMA model
  std::vector<std::string> sets;  // "name=value" (gmasim::apply_assignments)
};
void add_model_options(CLI::App* sub, ModelArgs& a,
                       const std::string& what = "Model file (TOML); default: the built-in MDMA "
                                                 "model");
ModelSpec load_model_spec_args(const ModelArgs& a);  // the file (or built-in) with --set applied
Model load_model_args(const ModelArgs& a);           // ... compiled
// "models/mdma.toml (built-in)" or the path, plus " with --set a=1, b=2" when there are any.
std::string model_label(const ModelArgs& a);

// Shared helpers.
std::string model_label(const std::string& path);  // "models/mdma.toml (built-in)" or path
void print_error(const std::string& what);
// Throws InputError if a floating-point flag of the parsed command is NaN or infinite.
void require_finite_numbers(const CLI::App& app);

}  // namespace gmasim::cli
