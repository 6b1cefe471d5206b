// gmasim: command-line front end. Exit codes: 0 ok, 1 usage, 2 bad input,
// 3 numerical divergence (partial output written), 4 internal error.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <vector>

#include "commands.hpp"
#include "gmasim/errors.hpp"

namespace gmasim::cli {

void print_error(const std::string& what) {
  std::fprintf(stderr, "gmasim: error: %s\n", what.c_str());
}

std::string model_label(const std::string& path) {
  return path.empty() ? std::string("models/mdma.toml (built-in)") : path;
}

}  // namespace gmasim::cli

int main(int argc, char** argv) {
  CLI::App app{
      "gmasim: temperature-dependent simulator of giant magnetostrictive actuators (the MCTD "
      "model; built-in model: the MDMA prototype). SI units inside; units are named in every "
      "flag and output column."};
  app.require_subcommand(1);
  std::vector<gmasim::cli::Runner> runners;
  runners.push_back(gmasim::cli::add_simulate(app));
  runners.push_back(gmasim::cli::add_model(app));
  runners.push_back(gmasim::cli::add_reproduce(app));
  runners.push_back(gmasim::cli::add_identify(app));
  runners.push_back(gmasim::cli::add_sweep(app));
  runners.push_back(gmasim::cli::add_frf(app));
  runners.push_back(gmasim::cli::add_track(app));
  runners.push_back(gmasim::cli::add_ablate(app));
  runners.push_back(gmasim::cli::add_params(app));
  runners.push_back(gmasim::cli::add_thermal(app));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    // Each runner checks whether its subcommand was parsed and returns -1 if not.
    for (auto& run : runners) {
      const int rc = run();
      if (rc >= 0) return rc;
    }
    return 1;
  } catch (const gmasim::InputError& e) {
    gmasim::cli::print_error(e.what());
    return 2;
  } catch (const gmasim::DivergenceError& e) {
    gmasim::cli::print_error(e.what());
    return 3;
  } catch (const std::exception& e) {
    gmasim::cli::print_error(fmt::format("internal error: {}", e.what()));
    return 4;
  }
}
