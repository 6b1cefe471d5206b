// Input and output: TOML model files, waveform CSV, atomic output files.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gmasim/experiments/experiments.hpp"
#include "gmasim/model/model.hpp"
#include "gmasim/simulate/simulate.hpp"

namespace gmasim {

// The built-in model (models/mdma.toml compiled into the library).
extern const char* const kBuiltinModelToml;
extern const char* const kBuiltinModelName;

// Parses and validates a model file against the schema (docs/model.md, "Model file"):
// malformed TOML, unknown keys, missing keys, wrong types, NaN/Inf, non-positive
// lengths/areas/masses/stiffnesses/reluctances, bad option values. Every problem is an
// InputError "file:line: message naming the value and the rule". `load_model_spec`
// collects all problems of a file and reports them together (one per line).
ModelSpec parse_model_spec(const std::string& toml_text, const std::string& source_name);
ModelSpec load_model_spec(const std::string& path);
ModelSpec builtin_model_spec();

// Convenience: load (path empty -> built-in) and compile.
Model load_model(const std::string& path);

// Applies "name=value" assignments (the --set flag of every command; Python
// Model.with_params): a number to a parameter by its dotted name with its unit suffix
// (ModelSpec::key_of: a dimensional key without it is refused), or a word to an option
// ("options.magnetic_state=printed", under ModelSpec::set_option's). `flag` names the source in
// messages. Throws InputError.
ModelSpec apply_assignments(ModelSpec spec, const std::vector<std::string>& assignments,
                            std::string_view flag = "--set");

// The spec as a model file: its source text (ModelSpec::text) with every value that differs
// from the text's own replaced on its line; a changed value's comment becomes
// "set: <why>; was <old> (<old provenance>)". The result is re-parsed, must carry exactly the
// spec's values and must compile. save_model writes it atomically.
std::string model_toml(const ModelSpec& spec, const std::string& why);
void save_model(const ModelSpec& spec, const std::string& path, const std::string& why);

// One row per parameter, option, meta text and structure key, in file order: dotted name,
// value, unit, provenance (the line's comment), line, and meaning (the parameter table's doc).
struct ParamRow {
  std::string name, value, unit, provenance;
  long line;
  std::string doc;
};
std::vector<ParamRow> describe_model(const ModelSpec& spec);

// Waveform CSV: header "t_s,current_A", then numeric rows, strictly increasing time.
// Throws InputError with file:line for an empty file, a bad header, non-numeric cells,
// NaN/Inf, or time that does not increase.
Waveform load_waveform_csv(const std::string& path);

// Writes `content` to `path` atomically: a temporary file in the same directory, flushed,
// then renamed over the target. Throws InputError if the directory cannot be written, or if
// something other than a regular file (a device, a FIFO, a directory) sits at `path`: an
// output never replaces it (issue 8).
void write_file_atomic(const std::string& path, const std::string& content);

// Writes several files as one: every temporary file is written and flushed first, then all
// are renamed, so a run killed before the renames leaves the previous set untouched and one
// killed between them leaves each file complete (a reader pairs them by the run stamp they
// carry, e.g. metrics.json's "steps"). The renames hold an exclusive flock() on their
// directory, so two processes writing a set into one directory never leave a mix of both
// (issue 19, item 5). Same checks as write_file_atomic.
void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& path_content);

// Removes the temporaries of every write in progress (issue 19, item 5). Async-signal-safe
// (unlink(2) only): the CLI calls it from its SIGINT/SIGTERM/SIGHUP handler before the signal
// ends the process, so a killed run leaves no "<file>.tmp.<pid>" behind. A temporary that a
// SIGKILL left is removed by the next write of the same file (its process is gone).
void remove_pending_temporaries() noexcept;

// Reads a user's input file whole: at most kMaxInputBytes (gmasim/model/validate.hpp), else an
// InputError "<path>: <what> is larger than ..."; `what` names the file in messages.
std::string read_input_file(const std::string& path, const std::string& what);

// Creates the directory (and parents) if needed and checks it is writable. An empty name is
// refused (InputError "output directory '': ..."), never taken for the current directory.
void ensure_output_dir(const std::string& dir);
// Removes the directories ensure_output_dir() created in this process that are still empty (a
// run refused after its output directory was made leaves nothing behind; one that wrote part
// of its output keeps it).
void remove_created_output_dirs_if_empty();

// No output may overwrite an input (issue 19, item 1; docs/reliability.md, "Outputs"). A file
// a command reads or writes, and the flag that names it in messages ("--out", "--data").
struct FileArg {
  std::string path;
  std::string flag;
};
// Throws InputError if an output is one of the inputs, or two outputs of different flags are
// one file: the same existing file (device and inode: hard links, symbolic links and other
// spellings of a path are caught), else the same absolute path with the symbolic links of its
// existing part resolved. An output whose file name holds '*' (DIR/sweep_*.csv: a family of
// files a command writes) matches every input it globs. An input with an empty path is skipped.
// Pairs of flags in `allowed` are exempt (identify's --resume and --checkpoint: a run continues
// the checkpoint it resumed). Every command calls it before any work.
void require_outputs_distinct(const std::vector<FileArg>& inputs,
                              const std::vector<FileArg>& outputs,
                              const std::vector<std::pair<std::string, std::string>>& allowed = {});
// DIR/name for each name, all under one flag (a command's files in its output directory).
std::vector<FileArg> files_in(const std::string& dir, const std::vector<std::string>& names,
                              const std::string& flag);

std::string timeseries_csv(const TimeSeries& ts);

// An experiment's report table as CSV (one row per point; a non-finite number is an empty
// cell), and the whole report as one JSON document:
// {"experiment": ..., "meta": {...}, "tables": {"name": {"columns": [...], "rows": [{...}]}}}
std::string table_csv(const Table& t);
std::string report_json(const Report& r);

// Writes an experiment's report: DIR/<stem>.json (every table) and one CSV per table,
// DIR/<stem>.csv for the first and DIR/<stem>_<table>.csv for the others, atomically.
// Returns the paths written.
std::vector<std::string> write_report_files(const std::string& dir, const std::string& stem,
                                            const Report& r);
// metrics.json: settings, metrics, status; `extra` holds more "key": value lines.
// With the text of the timeseries.csv written beside it, the file records that text's size
// and FNV-1a 64-bit hash ("timeseries_csv": {"bytes", "fnv1a64"}), so a reader can check
// that the two files belong to the same run.
std::string metrics_json(const Result& r, const SimulationSettings& s, const Model& m,
                         std::string_view timeseries_csv_text = {});
// FNV-1a 64-bit hash of data, as 16 hex digits.
std::string fnv1a64_hex(std::string_view data);

// `python -m module args...`: how the library and the CLI run the Python package that draws
// the figures (gmasim.command_figures, gmasim.report_figures). Started with posix_spawnp
// (no shell: the arguments are passed as they are, a path with quotes or spaces is safe);
// the child's environment is ours with MPLBACKEND=Agg and, when python_path is not empty,
// PYTHONPATH = python_path followed by our PYTHONPATH.
struct PythonCommand {
  std::string python = "/usr/bin/python3";  // a path, or a name looked up in PATH
  std::string python_path;                  // where the gmasim package is; "" = as we have it
  std::string module;                       // run with -m
  std::vector<std::string> args;
  bool stdout_to_stderr = false;  // the child's standard output goes to our standard error
  std::string text() const;       // "python -m module args..." for messages
};
// Runs it and waits: the exit status (0: success), 127 if it could not be started, 128 + N
// if signal N ended it. The child's standard error is ours.
int run_python(const PythonCommand& c);
// Whether run_python can start `python`: a path with '/' as it is, a bare name on PATH (as
// posix_spawnp looks it up); an executable regular file either way.
bool python_runnable(const std::string& python);

}  // namespace gmasim
