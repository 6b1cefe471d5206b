// The helpers every subcommand of the gmasim CLI uses (commands.hpp): model options and
// files, messages, warnings and the fatal-signal handler. main.cpp holds only main() and the
// version text, so that the command files and main() do not call into each other.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <new>
#include <string>
#include <vector>

#include "commands.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/validity.hpp"

namespace gmasim::cli {

int env_int(const char* name, int fallback) {
  const char* v = std::getenv(name);
  return v ? std::atoi(v) : fallback;
}

// stdout is flushed first: when both streams go to one file or pipe (2>&1), a message then
// comes after the lines printed before it, not ahead of the buffered header (issue 41).
void print_error(const std::string& what) {
  std::fflush(stdout);
  std::fprintf(stderr, "gmasim: error: %s\n", what.c_str());
}

// Every floating-point flag of the parsed command must be a finite number: "nan" and "inf"
// parse as doubles, and an unused flag (--step-time nan without a step waveform) would
// otherwise pass silently (issue 8). CLI11 names such options' type "FLOAT".
namespace {
// No value may be empty either: CLI11 converts '' to 0 for a number and to the flag's default for
// a path (--temperatures '' ran at 0 degC, --model '' took the built-in model).
void check_options(const CLI::App& app) {
  for (const CLI::Option* o : app.get_options()) {
    if (o->get_items_expected_max() > 0)
      for (const std::string& v : o->results())
        if (v.empty())
          throw InputError(fmt::format(
              "{} '': an empty value (give a value, or leave the flag out for its default)",
              o->get_name()));
    // An unsigned flag wraps a negative value (track --seed -1 ran as 2^64 - 1) and a 64-bit one
    // saturates beyond its range (99999999999999999999999 did the same): refused.
    if (o->get_type_name().find("INT") != std::string::npos) {
      const bool is_unsigned = o->get_type_name().find("UINT") != std::string::npos;
      for (const std::string& v : o->results()) {
        const char* b = v.c_str() + (v.starts_with('+') ? 1 : 0);
        const char* e = v.c_str() + v.size();
        if (is_unsigned && v.starts_with('-'))
          throw InputError(
              fmt::format("{} {}: must be >= 0", o->get_name(), clip_error_message(v)));
        // CLI11 also reads 0x / 0o / 0b prefixes: the digits after them, in that base
        const char* digits = b + (*b == '-' ? 1 : 0);
        int base = 10;
        if (e - digits > 2 && digits[0] == '0') {
          const char c = static_cast<char>(digits[1] | 0x20);
          base = c == 'x' ? 16 : c == 'o' ? 8 : c == 'b' ? 2 : 10;
        }
        long long sv = 0;
        unsigned long long uv = 0;
        std::from_chars_result r{};
        if (base == 10)
          r = is_unsigned ? std::from_chars(b, e, uv) : std::from_chars(b, e, sv);
        else if (*b != '-')
          r = is_unsigned ? std::from_chars(digits + 2, e, uv, base)
                          : std::from_chars(digits + 2, e, sv, base);
        if (r.ec == std::errc::result_out_of_range)
          throw InputError(fmt::format("{} {}: out of range (a 64-bit whole number)", o->get_name(),
                                       clip_error_message(v)));
      }
    }
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

// A command that fails -- an exception in main(), or a non-zero exit of its own -- leaves no
// output directory it created empty; one that wrote part of its output keeps it (rmdir only).
struct EmptyOutputDirs {
  int rc = 1;  // the command's exit status, once it returned one
  ~EmptyOutputDirs() {
    if (rc != 0) remove_created_output_dirs_if_empty();
  }
};

CLI::Validator model_path_transform() {
  return CLI::Validator(
      [](std::string& path) {
        path = resolve_model_path(path);
        return std::string();
      },
      "", "shipped model");
}

std::string model_label(const std::string& path) {
  return path.empty() ? std::string("the built-in MDMA model (models/mdma.toml, compiled in)")
                      : path;
}

std::string beside_executable(const std::string& relative) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path dir = (exe.parent_path().parent_path() / relative).lexically_normal();
  return fs::is_directory(dir, ec) ? dir.string() : std::string();
}

// The installed models (<prefix>/share/gmasim/models), or the build tree's copy of them at the
// same place relative to the executable.
std::string shipped_models_dir() {
  if (const char* env = std::getenv("GMASIM_MODELS_DIR"); env && *env) return env;
  return beside_executable("share/gmasim/models");
}

std::string resolve_model_path(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (path.empty() || fs::exists(path, ec)) return path;
  const fs::path p(path);
  const bool bare = !p.has_parent_path() || p.parent_path() == "models";
  const std::string dir = shipped_models_dir();
  if (!bare || dir.empty()) return path;
  fs::path shipped = fs::path(dir) / p.filename();
  // A bare name without its extension ("single_rod_preisach"): the shipped file of that name.
  if (!fs::is_regular_file(shipped, ec) && !p.has_extension()) shipped += ".toml";
  return fs::is_regular_file(shipped, ec) ? shipped.string() : path;
}

void add_model_options(CLI::App* sub, ModelArgs& a, const std::string& what) {
  sub->add_option("--model", a.path,
                  what +
                      ". A shipped model's name (mdma_printed.toml, models/single_rod.toml) "
                      "that is no file here is read from the installed models directory "
                      "(<prefix>/share/gmasim/models, or $GMASIM_MODELS_DIR)")
      ->transform(model_path_transform());
  sub->add_option("--set", a.sets,
                  "Change a model parameter for this run: name=value in the file's units (e.g. "
                  "--set material.Ms_A_per_m=7e5 --set options.magnetic_state=printed); "
                  "repeatable; `gmasim model show` lists the names");
}

ModelSpec load_model_spec_args(const ModelArgs& a) {
  ModelSpec spec = a.path.empty() ? builtin_model_spec() : load_model_spec(a.path);
  return apply_assignments(std::move(spec), a.sets, "--set");
}

Model load_model_args(const ModelArgs& a) {
  Model m = compile(load_model_spec_args(a));
  print_model_warnings(m);
  return m;
}

void print_warning(const std::string& what) {
  std::fflush(stdout);
  std::fprintf(stderr, "gmasim: warning: %s\n", what.c_str());
}

void print_model_warnings(const Model& m) {
  for (const auto& w : model_warnings(m)) print_warning(w);
}

void warn_temperatures(const Model& m, const std::vector<double>& temperatures_C,
                       const std::string& flag) {
  std::vector<double> outside;
  for (const double T : temperatures_C)
    if (temperature_warning(m, T) && std::find(outside.begin(), outside.end(), T) == outside.end())
      outside.push_back(T);
  if (outside.empty()) return;
  if (outside.size() > 8) outside.resize(8);
  print_warning(fmt::format(
      "{} {} degC: outside the range where {} was validated, {} (validity.validated_min_C/max_C); "
      "the results there are an extrapolation",
      flag, fmt::join(outside, ", "), m.spec.source, range_text(validated_range(m))));
}

std::vector<FileArg> model_inputs(const ModelArgs& a) {
  if (a.path.empty()) return {};
  return {{a.path, "--model"}};
}

void prepare_output_dir(const std::string& dir, const std::vector<std::string>& stems,
                        const std::vector<FileArg>& inputs) {
  if (dir.empty()) ensure_output_dir(dir);  // refuses the empty name first
  std::vector<std::string> names;
  for (const auto& s : stems) names.push_back(s + "*");
  require_outputs_distinct(inputs, files_in(dir, names, "--out"));
  ensure_output_dir(dir);
}

std::string model_label(const ModelArgs& a) {
  std::string s = model_label(a.path);
  if (!a.sets.empty())
    s += " with --set " + clip_error_message(fmt::format("{}", fmt::join(a.sets, ", ")));
  return s;
}

}  // namespace gmasim::cli

namespace {

// SIGINT, SIGTERM, SIGHUP: the temporaries of a write in progress are removed, then the signal
// ends the process as it would have (issue 19, item 5). SIGXFSZ (a file over `ulimit -f`) is
// ignored, so that write() fails with EFBIG and the run reports the file and the limit instead
// of dying without a word.
extern "C" void on_fatal_signal(int sig) {
  gmasim::remove_pending_temporaries();
  // write(2) only: async-signal-safe. The files of a finished write are whole; none is partial.
  static const char msg[] = "gmasim: stopped by a signal; no partial output file is left\n";
  (void)!::write(STDERR_FILENO, msg, sizeof msg - 1);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

namespace gmasim::cli {
void install_fatal_signal_handler(int sig) { std::signal(sig, on_fatal_signal); }
}  // namespace gmasim::cli
