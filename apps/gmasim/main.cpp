// gmasim: command-line front end. Exit codes: 0 ok, 1 usage, 2 bad input,
// 3 numerical divergence (partial output written), 4 internal error. A parse error (an
// unknown flag, a value that is not a number, a non-finite number) is a usage error, 1.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <vector>

#include "commands.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io.hpp"
#include "gmasim/version.h"

namespace gmasim::cli {

void print_error(const std::string& what) {
  std::fprintf(stderr, "gmasim: error: %s\n", what.c_str());
}

// Every floating-point flag of the parsed command must be a finite number: "nan" and "inf"
// parse as doubles, and an unused flag (--step-time nan without a step waveform) would
// otherwise pass silently (issue 8). CLI11 names such options' type "FLOAT".
namespace {
void check_options(const CLI::App& app) {
  for (const CLI::Option* o : app.get_options()) {
    if (o->get_type_name().find("FLOAT") == std::string::npos) continue;
    for (const std::string& v : o->results()) {
      char* end = nullptr;
      const double d = std::strtod(v.c_str(), &end);
      if (end != v.c_str() && !std::isfinite(d))
        throw InputError(
            fmt::format("{} {}: must be a finite number", o->get_name(), clip_error_message(v)));
    }
  }
  for (const CLI::App* sub : app.get_subcommands()) check_options(*sub);
}
}  // namespace

void require_finite_numbers(const CLI::App& app) { check_options(app); }

std::string model_label(const std::string& path) {
  return path.empty() ? std::string("models/mdma.toml (built-in)") : path;
}

void add_model_options(CLI::App* sub, ModelArgs& a, const std::string& what) {
  sub->add_option("--model", a.path, what);
  sub->add_option("--set", a.sets,
                  "Change a model parameter for this run: name=value in the file's units (e.g. "
                  "--set material.Ms_A_per_m=7e5 --set options.magnetic_state=printed); "
                  "repeatable; `gmasim model show` lists the names");
}

ModelSpec load_model_spec_args(const ModelArgs& a) {
  ModelSpec spec = a.path.empty() ? builtin_model_spec() : load_model_spec(a.path);
  return apply_assignments(std::move(spec), a.sets, "--set");
}

Model load_model_args(const ModelArgs& a) { return compile(load_model_spec_args(a)); }

std::string model_label(const ModelArgs& a) {
  std::string s = model_label(a.path);
  if (!a.sets.empty()) s += " with --set " + clip_error_message(fmt::format("{}", fmt::join(a.sets, ", ")));
  return s;
}

}  // namespace gmasim::cli

int main(int argc, char** argv) {
  CLI::App app{
      "gmasim: temperature-dependent simulator of giant magnetostrictive actuators (the MCTD "
      "model; built-in model: the MDMA prototype). SI units inside; units are named in every "
      "flag and output column."};
  app.require_subcommand(1);
  // "gmasim 0.1.0", plus the git describe of the source tree at configure time if it had one.
  const std::string git_describe = GMASIM_GIT_DESCRIBE;
  app.set_version_flag("--version", std::string("gmasim " GMASIM_VERSION) +
                                        (git_describe.empty() ? "" : " (" + git_describe + ")"),
                       "Print the version and exit");
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
  runners.push_back(gmasim::cli::add_compensate(app));
  runners.push_back(gmasim::cli::add_sensitivity(app));
  try {
    app.parse(argc, argv);
    gmasim::cli::require_finite_numbers(app);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // Every parse error is a usage error, exit 1 (CLI11's own codes are 100+), with the
    // message clipped so that a hostile value is not echoed whole.
    gmasim::cli::print_error(gmasim::clip_error_message(e.what()));
    std::fprintf(stderr, "Run with --help for more information.\n");
    return 1;
  } catch (const gmasim::InputError& e) {
    gmasim::cli::print_error(e.what());
    return 1;
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
