// gmasim: command-line front end. Exit codes: 0 ok, 1 usage, 2 bad input,
// 3 numerical divergence (partial output written), 4 internal error. A parse error (an
// unknown flag, a value that is not a number, a non-finite number) is a usage error, 1.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "commands.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "gmasim/version.h"

namespace {

// "gmasim 0.1.0", plus the git describe of the source tree at configure time if it had one,
// and the SIMD target the lanes chose on this CPU with its width (run-time dispatch, so a log
// can be tied to a machine: scripts/test.sh prints it for .ci/run, issue 36).
std::string version_text() {
  const std::string git_describe = GMASIM_GIT_DESCRIBE;
  return std::string("gmasim " GMASIM_VERSION) +
         (git_describe.empty() ? "" : " (" + git_describe + ")") +
         fmt::format("\nlanes: SIMD target {}, {} doubles per vector", gmasim::lanes_target(),
                     gmasim::lanes_width());
}

}  // namespace

int main(int argc, char** argv) {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) gmasim::cli::install_fatal_signal_handler(sig);
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{
      "gmasim: temperature-dependent simulator of giant magnetostrictive actuators (the MCTD "
      "model; built-in model: the MDMA prototype). SI units inside; units are named in every "
      "flag and output column."};
  app.require_subcommand(1);
  app.set_version_flag("--version", version_text,
                       "Print the version and the SIMD target the lanes use on this CPU, and exit");
  std::vector<gmasim::cli::Runner> runners;
  runners.push_back(gmasim::cli::add_simulate(app));
  runners.push_back(gmasim::cli::add_model(app));
  runners.push_back(gmasim::cli::add_reproduce(app));
  runners.push_back(gmasim::cli::add_identify(app));
  runners.push_back(gmasim::cli::add_sweep(app));
  runners.push_back(gmasim::cli::add_frf(app));
  runners.push_back(gmasim::cli::add_linearize(app));
  runners.push_back(gmasim::cli::add_track(app));
  runners.push_back(gmasim::cli::add_ablate(app));
  runners.push_back(gmasim::cli::add_params(app));
  runners.push_back(gmasim::cli::add_thermal(app));
  runners.push_back(gmasim::cli::add_compensate(app));
  runners.push_back(gmasim::cli::add_sensitivity(app));
  runners.push_back(gmasim::cli::add_design(app));
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
    // message clipped so that a hostile value is not echoed whole; an unknown word gets the
    // nearest command or flag suggested, a value that is not a number the unit it takes.
    gmasim::cli::print_error(
        gmasim::clip_error_message(gmasim::cli::parse_error_message(app, e, argc, argv)));
    std::fprintf(stderr, "Run with --help for more information.\n");
    return 1;
  } catch (const gmasim::InputError& e) {
    gmasim::cli::print_error(e.what());
    return 1;
  }
  gmasim::cli::EmptyOutputDirs dirs;  // removed unless the command exits 0
  try {
    // Each runner checks whether its subcommand was parsed and returns -1 if not.
    for (auto& run : runners) {
      const int rc = run();
      if (rc >= 0) return dirs.rc = rc;
    }
    return 1;
  } catch (const gmasim::cli::UsageError& e) {
    gmasim::cli::print_error(e.what());
    return 1;
  } catch (const gmasim::InputError& e) {
    gmasim::cli::print_error(e.what());
    return 2;
  } catch (const gmasim::DivergenceError& e) {
    gmasim::cli::print_error(e.what());
    return 3;
  } catch (const std::bad_alloc&) {
    gmasim::cli::print_error(
        "out of memory: the run needs more memory than the system gives it (MemAvailable, "
        "ulimit -v); record less often (--record-every), shorten the run or lower --threads");
    return 2;
  } catch (const std::exception& e) {
    gmasim::cli::print_error(fmt::format("internal error: {}", e.what()));
    return 4;
  }
}
