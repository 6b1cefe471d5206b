// Subcommands of the gmasim CLI. Each registers its options on a CLI11 subcommand and
// returns the function that runs it (exit code). The CLI holds no physics.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"

namespace gmasim::cli {

using Runner = std::function<int()>;

// A usage error found after parsing (flags that contradict each other): exit 1, like CLI11's.
struct UsageError : InputError {
  using InputError::InputError;
};

// The message of a CLI11 parse error, made to name the word and the rule (cli_messages.cpp):
// "unknown command 'simulat'; did you mean 'simulate'?", "--temperature '80C': not a number
// (in degC, without the unit)", else CLI11's own text.
std::string parse_error_message(const CLI::App& app, const CLI::ParseError& e, int argc,
                                char** argv);

Runner add_simulate(CLI::App& app);
Runner add_model(CLI::App& app);
Runner add_reproduce(CLI::App& app);
Runner add_identify(CLI::App& app);     // cmd_identify.cpp: identify, identify synthesize
Runner add_sweep(CLI::App& app);        // cmd_sweep.cpp
Runner add_frf(CLI::App& app);          // cmd_frf.cpp
Runner add_linearize(CLI::App& app);    // cmd_linearize.cpp
Runner add_track(CLI::App& app);        // cmd_track.cpp
Runner add_ablate(CLI::App& app);       // cmd_ablate.cpp
Runner add_params(CLI::App& app);       // cmd_params.cpp: params-vs-temperature
Runner add_thermal(CLI::App& app);      // cmd_params.cpp: thermal
Runner add_compensate(CLI::App& app);   // cmd_compensate.cpp
Runner add_sensitivity(CLI::App& app);  // cmd_sensitivity.cpp
Runner add_design(CLI::App& app);       // cmd_design.cpp

// --model FILE and --set name=value (repeatable), on every command that runs a model.
struct ModelArgs {
  std::string path;               // empty: the built-in MDMA model
  std::vector<std::string> sets;  // "name=value" (gmasim::apply_assignments)
};
void add_model_options(CLI::App* sub, ModelArgs& a,
                       const std::string& what =
                           "Model file (TOML); default: the built-in MDMA "
                           "model");
ModelSpec load_model_spec_args(const ModelArgs& a);  // the file (or built-in) with --set applied
Model load_model_args(const ModelArgs& a);           // ... compiled
// "models/mdma.toml (built-in)" or the path, plus " with --set a=1, b=2" when there are any.
std::string model_label(const ModelArgs& a);
// The model file as an input of the command ({} for the built-in model).
std::vector<FileArg> model_inputs(const ModelArgs& a);
// An experiment's output directory: refuses it if a file the command writes there (stems:
// "sweep" covers sweep*.csv|json|png|svg) would overwrite an input, then ensure_output_dir.
void prepare_output_dir(const std::string& dir, const std::vector<std::string>& stems,
                        const std::vector<FileArg>& inputs);

// <exe>/../<relative> when that directory exists, else "": how the CLI finds what ships beside
// it, the same in an install prefix and in the build tree (no absolute path compiled in).
std::string beside_executable(const std::string& relative);
// The shipped model files (docs/model.md, "Model files"): $GMASIM_MODELS_DIR, else
// <exe>/../share/gmasim/models (the installed prefix's, or the build tree's copy); "" if neither.
std::string shipped_models_dir();
// A --model value that names no file here but a shipped model ("mdma_printed.toml",
// "models/mdma_printed.toml"): the shipped file's path; any other value unchanged.
std::string resolve_model_path(const std::string& path);
CLI::Validator model_path_transform();  // resolve_model_path as a CLI11 transform

// Shared helpers.
int env_int(const char* name, int fallback);  // an integer environment variable, or fallback
// Runs body on the command's processes: MPI ranks when `mpi` is "on", or "auto" and mpirun/srun
// launched it; one process otherwise (refused under mpirun with more than one rank). An
// InputError is printed by rank 0 (exit 2), any other exception by its rank (exit 4); with
// several ranks either ends them all (MPI_Abort) after removing the command's empty output
// directories.
int run_on_ranks(const std::string& mpi, const std::string& command,
                 const std::function<int(Communicator&)>& body);
// --threads on a rank: as given (>= 1), or 0: the cores over the ranks on this node
// (OMPI_COMM_WORLD_LOCAL_SIZE). InputError for a negative count.
int threads_per_rank(int requested, const Communicator& comm);
std::string model_label(const std::string& path);  // "models/mdma.toml (built-in)" or path
void print_error(const std::string& what);
void print_warning(const std::string& what);  // "gmasim: warning: ..." on stderr
// The handler that removes the temporaries of a write in progress and lets `sig` end the
// process (main installs it for SIGINT, SIGTERM, SIGHUP; identify's second signal gets it).
void install_fatal_signal_handler(int sig);
// The model's values far outside Terfenol-D's known range (gmasim/model/validity.hpp), as warnings.
void print_model_warnings(const Model& m);
// One warning naming `flag` and the temperatures outside the model's validated range.
void warn_temperatures(const Model& m, const std::vector<double>& temperatures_C,
                       const std::string& flag);
// Throws InputError if a floating-point flag of the parsed command is NaN or infinite.
void require_finite_numbers(const CLI::App& app);

}  // namespace gmasim::cli
