// Shared pieces of the experiment subcommands (sweep, frf, track, ablate,
// params-vs-temperature, thermal): list parsing, progress on stderr, report files.
#pragma once

#include <string>
#include <vector>

#include "gmasim/experiments/experiments.hpp"

namespace gmasim::cli {

// "20,30,40" or "20:10:70" (start:step:stop, inclusive) or a mix "6,8:2:12"; "" -> empty.
// Throws InputError naming the flag and its unit.
std::vector<double> parse_list(const std::string& text, const std::string& flag,
                               const std::string& unit);

// Progress on stderr ("label: 12/24 points"), when stderr is a terminal or `force`.
// Returns an empty function when progress is off.
ProgressFn stderr_progress(const std::string& label, bool force);

// Writes DIR/<stem>.json (every table) and one CSV per table: DIR/<stem>.csv for the
// first, DIR/<stem>_<table>.csv for the others. Returns the paths written.
std::vector<std::string> write_report(const std::string& dir, const std::string& stem,
                                      const Report& r);

// Where the gmasim Python package is: $GMASIM_PYTHONPATH, else the build tree's package.
std::string python_package_path();

// Renders the figure of a command's outputs in `dir` with the Python package
// (`/usr/bin/python3 -m gmasim.command_figures <command> <dir>` through run_python: no shell).
// Returns the PNG path. Throws InputError if the renderer fails (its stderr is passed
// through).
std::string render_plot(const std::string& command, const std::string& dir);

}  // namespace gmasim::cli
