// Subcommands of the gmasim CLI. Each registers its options on a CLI11 subcommand and
// returns the function that runs it (exit code). The CLI holds no physics.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace gmasim::cli {

using Runner = std::function<int()>;

Runner add_simulate(CLI::App& app);
Runner add_model(CLI::App& app);

// Shared helpers.
std::string model_label(const std::string& path);  // "models/mdma.toml (built-in)" or path
void print_error(const std::string& what);

}  // namespace gmasim::cli
