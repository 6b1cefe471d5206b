// gmasim identify: measured data + fit spec -> calibrated model file and fit report.
// gmasim identify synthesize: synthetic measurements from a model (validation, examples).
// Only this command initialises MPI, and only when launched by mpirun/srun (or --mpi on).
#include <fmt/format.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <thread>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/identify/synthetic_fields.hpp"
#include "gmasim/io/io.hpp"
#include "request_options.hpp"

namespace gmasim::cli {
namespace {

namespace fs = std::filesystem;

// Set by SIGINT / SIGTERM / SIGUSR1 (mpirun forwards SIGUSR1 to every rank); the search
// stops at the end of the current epoch and writes the best model so far.
std::atomic<bool> g_stop{false};

extern "C" void on_stop_signal(int sig) {
  g_stop.store(true);
  // A second signal ends the process at once (after removing the temporaries of a write).
  install_fatal_signal_handler(sig);
}

struct IdentifyArgs {
  std::string data, fit, out, report, mpi = "auto";
  ModelArgs model;
  IdentifyOptions opt;
  bool no_refine = false, no_profile = false, no_plots = false, quiet = false;
};

struct SynthArgs {
  std::string out;
  ModelArgs model;
  SyntheticRequest req;
  RequestOptions<SyntheticRequest> options;  // its table's options
  bool no_flux = false;
  std::string drive = "current", response = "displacement", offset = "absolute";
  std::string initial_state = "demagnetised";
};

// The command line, for provenance (Linux: /proc/self/cmdline).
std::string command_line() {
  std::ifstream f("/proc/self/cmdline", std::ios::binary);
  std::string all((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::string cmd;
  std::size_t start = 0;
  bool first = true;
  while (start < all.size()) {
    const auto end = all.find('\0', start);
    std::string a = all.substr(start, end - start);
    if (first) a = fs::path(a).filename().string();
    first = false;
    const bool plain = !a.empty() && a.find_first_of(" \t'\"\\$`!*?;&|<>()") == std::string::npos;
    if (!cmd.empty()) cmd += ' ';
    cmd += plain ? a : "'" + a + "'";
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return cmd.empty() ? "gmasim identify" : cmd;
}

// What identify reads: the start model, the manifest and its measurement files, the fit spec
// (when it is a file) and the checkpoint it resumes.
std::vector<FileArg> identify_inputs(const IdentifyArgs& a, const MeasurementSet& data) {
  std::vector<FileArg> in = model_inputs(a.model);
  in.push_back({a.data, "--data"});
  for (const auto& m : data.items) in.push_back({m.path, "--data (a measurement file)"});
  std::error_code ec;
  if (fs::is_regular_file(a.fit, ec)) in.push_back({a.fit, "--fit"});
  in.push_back({a.opt.resume_path, "--resume"});
  return in;
}

// What it writes: the model, the checkpoint, the report directory's files.
std::vector<FileArg> identify_outputs(const IdentifyArgs& a) {
  // the report directory itself too: --report equal to --out created a directory where the
  // model was to be written, and the finished search was lost
  std::vector<FileArg> out = {{a.out, "--out"}, {a.report, "--report"}};
  if (!a.opt.checkpoint_path.empty()) out.push_back({a.opt.checkpoint_path, "--checkpoint"});
  for (auto& f : files_in(
           a.report,
           {"fit_report.json", "fit_report.md", "convergence.csv", "convergence.png", "overlay_*"},
           "--report"))
    out.push_back(std::move(f));
  return out;
}

void write_outputs(const IdentifyArgs& a, const IdentifyResult& r, const ModelSpec& start) {
  FitProvenance p;
  p.command = command_line();
  p.data = a.data;
  p.fit = a.fit;
  p.start_model = model_label(a.model);
  p.report_dir = a.report;
  p.fitted_claims = fitted_claims(load_fit_spec(a.fit));
  // The start's own text: the file as read, with any --set values written into it.
  // A --set of an option the file omits adds a line, so the lines are those of that text.
  const bool set = !a.model.sets.empty();
  const std::string start_text = set ? model_toml(start, "--set") : start.text;
  const ModelSpec start_as_written = set ? parse_model_spec(start_text, start.source) : start;
  const fs::path out(a.out);
  if (out.has_parent_path()) ensure_output_dir(out.parent_path().string());
  write_file_atomic(a.out, fitted_model_toml(start_text, start_as_written, r, p));
  ensure_output_dir(a.report);
  const fs::path dir(a.report);
  write_file_atomic((dir / "fit_report.json").string(), fit_report_json(r, p));
  write_file_atomic((dir / "fit_report.md").string(), fit_report_markdown(r, p));
  write_file_atomic((dir / "convergence.csv").string(), convergence_csv(r));
  for (const auto& c : r.conditions)
    if (!c.failed) write_file_atomic((dir / c.overlay_file).string(), timeseries_csv(c.overlay));
  if (!a.no_plots) {
    // overlay_<condition>.png and convergence.png, drawn from the files above.
    PythonCommand c;
    c.python_path = python_package_path();
    c.module = "gmasim.command_figures";
    c.args = {"identify", a.report};
    if (run_python(c) != 0) {
      std::fprintf(stderr,
                   "gmasim identify: note: plotting failed (matplotlib missing?); the CSV "
                   "overlays are written; draw them with `%s`\n",
                   c.text().c_str());
    }
  }
}

// The offsets the record's rules added to the simulated response (and flux), with units.
std::string offset_summary(const ConditionFit& c) {
  std::string s;
  if (c.condition.offset != OffsetMode::Absolute)
    s += fmt::format("; offset ({}) {:+.6g} {}", offset_mode_name(c.condition.offset), c.offset,
                     c.response_unit);
  if (c.flux_rms_pct >= 0 && c.condition.flux_offset != OffsetMode::Absolute)
    s += fmt::format("; flux offset ({}) {:+.6g} T", offset_mode_name(c.condition.flux_offset),
                     c.flux_offset_T);
  return s;
}

void print_summary(const IdentifyArgs& a, const IdentifyResult& r) {
  fmt::print("gmasim identify  {} parameters, {} conditions, {} targets\n", r.parameters.size(),
             r.conditions.size(), r.targets.size());
  fmt::print("  {} x {} islands x {} individuals ({}), {} generations{}; {}\n", r.ranks, r.islands,
             r.population, r.algorithm, r.generations_done, r.resumed ? " (resumed)" : "",
             r.refine_summary);
  fmt::print("  weighted RMS error {:.4g} % of p-p (start {:.4g} %, GA {:.4g} %)\n", r.rms_pct,
             r.start_rms_pct, r.ga_rms_pct);
  fmt::print("  {} evaluations in {:.1f} s ({}); GA {:.1f} evaluations/s\n", r.evaluations,
             r.wall_s, stage_text(r.stage_evaluations), r.ga_evals_per_s);
  fmt::print("  the written point was found by the {}\n", r.best_found_by);
  fmt::print("  {:<34} {:>13} {:>13}  {}\n", "parameter", "start", "fitted", "95 % CI");
  for (const auto& p : r.parameters) {
    std::string ci = "not determined by the data";
    if (std::isnan(p.ci_low)) ci = "no interval (interrupted)";
    if (p.determined) {
      ci = fmt::format("[{:.5g}, {:.5g}]{}", p.ci_low, p.ci_high,
                       p.ci_method == "profile" ? " profile" : "");
    }
    if (p.at_bound) ci += " (at a bound)";
    fmt::print("  {:<34} {:>13.6g} {:>13.6g}  {}\n", p.name, p.start, p.value, ci);
  }
  for (const auto& c : r.conditions) {
    if (c.failed)
      fmt::print("  {:<34} failed: {}\n", c.label, c.error);
    else
      fmt::print("  {:<34} RMS {:8.4f} {} = {:6.3f} %{}\n", c.label, c.rms, c.response_unit,
                 c.rms_pct, offset_summary(c));
  }
  for (const auto& t : r.targets)
    fmt::print("  {:<34} target {:.5g}, simulated {:.5g} ({:+.2f} %)\n", t.label, t.value,
               t.simulated, t.error_pct);
  for (const auto& n : r.notes) fmt::print("  note: {}\n", n);
  fmt::print("  wrote {} and {}/ (fit_report.md, fit_report.json, overlays, convergence)\n", a.out,
             a.report);
}

int run_identify_body(IdentifyArgs& a, Communicator& comm) {
  const bool root = comm.rank() == 0;
  if (a.data.empty() && a.fit.empty())
    throw InputError("identify: give --data MANIFEST and --fit SPEC (see docs/identify.md)");
  if (a.fit.empty()) throw InputError("identify: --fit SPEC is required");
  if (a.out.empty()) throw InputError("identify: --out model.toml is required");
  if (a.report.empty()) {
    fs::path p(a.out);
    a.report = (p.parent_path() / (p.stem().string() + "_report")).string();
  }
  const ModelSpec start = load_model_spec_args(a.model);
  const MeasurementSet data = a.data.empty() ? MeasurementSet{} : load_manifest(a.data);
  const FitSpec fit = load_fit_spec(a.fit);
  require_outputs_distinct(identify_inputs(a, data), identify_outputs(a),
                           {{"--resume", "--checkpoint"}});
  IdentifyOptions o = a.opt;
  o.refine = !a.no_refine;
  o.profile = !a.no_profile;
  o.comm = &comm;
  o.stop = &g_stop;
  o.threads = threads_per_rank(o.threads, comm);  // before a default could hide a negative one
  if (root) {
    // Fail on an unwritable destination before hours of search, not after: a file's path that
    // is a directory too.
    for (const auto& [path, flag] :
         {std::pair{a.out, "--out"}, std::pair{a.opt.checkpoint_path, "--checkpoint"}}) {
      std::error_code ec;
      if (!path.empty() && fs::is_directory(path, ec))
        throw InputError(fmt::format("{} {}: is a directory; name the file to write", flag,
                                     clip_for_message(path)));
    }
    const fs::path out(a.out);
    if (out.has_parent_path()) ensure_output_dir(out.parent_path().string());
    ensure_output_dir(a.report);
  }
  if (root && !a.quiet) {
    o.progress = [](const IdentifyProgress& p) {
      if (p.phase == "ga") {
        std::fprintf(stderr,
                     "gmasim identify: generation %d/%d  best %.4g %%  %ld evaluations  %.0f "
                     "evaluations/s  %.1f s\n",
                     p.generation, p.generations, p.best_rms_pct, p.evaluations, p.evals_per_s,
                     p.wall_s);
      } else if (p.phase == "profile") {
        std::fprintf(stderr,
                     "gmasim identify: profile %d/%d (%s)  point RMS %.5g %%  %ld evaluations  "
                     "%.1f s into the profile stage\n",
                     p.generation, p.generations, p.parameter.c_str(), p.best_rms_pct,
                     p.evaluations, p.wall_s);
      } else {
        std::fprintf(stderr,
                     "gmasim identify: refine iteration %d  RMS %.5g %%  %ld evaluations  %.1f s\n",
                     p.generation, p.best_rms_pct, p.evaluations, p.wall_s);
      }
    };
  }
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  std::signal(SIGUSR1, on_stop_signal);
  const IdentifyResult r = identify(start, data, fit, o);
  if (root) {
    write_outputs(a, r, start);
    if (!a.quiet) print_summary(a, r);
    if (r.interrupted) {
      std::fprintf(
          stderr, "gmasim identify: interrupted: wrote the best model so far (%s)%s\n",
          a.out.c_str(),
          o.checkpoint_path.empty() ? "" : "; continue with the same command and --resume");
    }
  }
  return r.interrupted ? 130 : 0;
}

int run_identify(IdentifyArgs& a) {
  return run_on_ranks(a.mpi, "identify",
                      [&](Communicator& comm) { return run_identify_body(a, comm); });
}

int run_synthesize(SynthArgs& a) {
  const ModelSpec spec = load_model_spec_args(a.model);
  std::string truth = fmt::format("# truth of the synthetic measurements\nmodel = \"{}\"\n",
                                  model_label(a.model.path));
  for (const auto& s : a.model.sets) {
    std::string name = s.substr(0, s.find('='));
    std::erase_if(name, [](char c) { return c == ' ' || c == '\t'; });
    if (name.starts_with("options.")) {
      truth += fmt::format("# {}\n", s);
    } else {
      truth += fmt::format("{} = {:.17g}\n", name, spec.get(name));
    }
  }
  if (a.no_flux) a.req.with_flux = false;
  a.req.drive = a.drive == "field" ? DriveInput::Field : DriveInput::Current;
  a.req.response = a.response == "strain" ? ResponseOutput::Strain : ResponseOutput::Displacement;
  a.req.offset = a.offset == "first_sample" ? OffsetMode::FirstSample
                 : a.offset == "fitted"     ? OffsetMode::Fitted
                                            : OffsetMode::Absolute;
  a.req.initial_state = a.initial_state == "negative_remanence"   ? InitialState::NegativeRemanence
                        : a.initial_state == "positive_remanence" ? InitialState::PositiveRemanence
                                                                  : InitialState::Demagnetised;
  const Model m = compile(spec);
  require_outputs_distinct(model_inputs(a.model),
                           files_in(a.out, {"manifest.toml", "truth.toml", "*.csv"}, "--out"));
  const MeasurementSet set = synthesize_measurements(m, a.req);
  write_measurement_set(set, a.out);
  write_file_atomic((fs::path(a.out) / "truth.toml").string(), truth);
  fmt::print(
      "gmasim identify synthesize: {} conditions ({} samples each, noise {:g} % of p-p) "
      "from {}\n  wrote {}/manifest.toml, the CSV files and truth.toml\n",
      set.items.size(), set.items.empty() ? 0 : set.items.front().t_s.size(), a.req.noise_pct,
      model_label(a.model), a.out);
  return 0;
}

// identify: its inputs and outputs.
void add_identify_files(CLI::App* sub, IdentifyArgs& a) {
  sub->add_option("--data", a.data, "Measurement manifest (TOML, docs/data.md)");
  sub->add_option("--fit", a.fit,
                  "Fit spec: TOML file ([[parameter]], [[target]]) or inline "
                  "'name:lower:upper[:log],...'");
  sub->add_option("--out", a.out, "Calibrated model file to write (TOML)");
  add_model_options(sub, a.model, "Start model (TOML); default: the built-in MDMA model");
  sub->add_option("--report", a.report,
                  "Fit report directory; default: <out>_report next to --out");
}

// identify: the global search (pagmo2 islands, MPI ranks).
void add_search_options(CLI::App* sub, IdentifyOptions& o) {
  sub->add_option(
         "--algorithm", o.algorithm,
         "Island algorithm: sga (the paper's GA), de, sade, cmaes, pso_gen (a generation's "
         "particles evaluated together in SIMD lanes)")
      ->check(CLI::IsMember(
          std::vector<std::string>(std::begin(kIslandAlgorithms), std::end(kIslandAlgorithms))))
      ->capture_default_str();
  sub->add_option("--islands", o.islands,
                  "Islands per rank (fixed: the result depends on it, not on the cores)")
      ->capture_default_str();
  sub->add_option("--population", o.population, "Individuals per island")->capture_default_str();
  sub->add_option("--generations", o.generations,
                  "Total GA generations (a resumed run continues up to this)")
      ->capture_default_str();
  sub->add_option("--migrate-every", o.migrate_every, "Generations between ring migrations")
      ->capture_default_str();
  sub->add_option("--migrants", o.migrants, "Individuals per migration (best out, worst replaced)")
      ->capture_default_str();
  sub->add_option("--mpi-every", o.mpi_every,
                  "Generations between champion exchanges over the MPI ring (0: --migrate-every)")
      ->capture_default_str();
  sub->add_option("--seed", o.seed, "Random seed")->capture_default_str();
  sub->add_option("--threads", o.threads,
                  "Worker threads evolving the islands and evaluating the Jacobian batches "
                  "(0: cores / ranks per node); the result does not depend on it")
      ->capture_default_str();
}

// identify: the Levenberg-Marquardt refinement and the intervals.
void add_refine_options(CLI::App* sub, IdentifyArgs& a) {
  sub->add_flag("--no-refine", a.no_refine, "Skip the Levenberg-Marquardt refinement");
  sub->add_flag("--no-profile", a.no_profile,
                "Linearised intervals only (no profile likelihood for parameters on a bound)");
  sub->add_option("--profile-evaluations", a.opt.profile_evaluations,
                  "Evaluations the profile-likelihood stage may spend (-1: as many as the "
                  "search; 0: no limit)")
      ->capture_default_str();
  sub->add_option("--refine-iterations", a.opt.refine_iterations,
                  "Levenberg-Marquardt iterations (max)")
      ->capture_default_str();
  sub->add_option("--fd-step", a.opt.fd_step,
                  "Finite-difference step of the Jacobian, fraction of each parameter's range")
      ->capture_default_str();
}

// identify: how each candidate is simulated and compared.
void add_objective_options(CLI::App* sub, ObjectiveSettings& s) {
  sub->add_option("--dt", s.dt_s,
                  "Time step of the measured records [s]; 0: period / --steps-per-period (scalar "
                  "targets take the claims' step of gmasim reproduce: T/2000, at most 25 us)")
      ->capture_default_str();
  sub->add_option("--steps-per-period", s.steps_per_period,
                  "Time steps per period of periodic measured records")
      ->capture_default_str();
  sub->add_option("--quasi-static-increments", s.quasi_static_increments,
                  "Quasi-static records: increments of the drive over its whole range")
      ->capture_default_str();
  sub->add_option("--flux-weight", s.flux_weight,
                  "Weight of the flux_T residuals of files that have them (0: ignore flux)")
      ->capture_default_str();
  sub->add_option("--target-periods", s.target_periods,
                  "Periods simulated for scalar targets (the last is measured; 3, as gmasim "
                  "reproduce's sweeps)")
      ->capture_default_str();
}

// identify: checkpoints, MPI, plots and progress.
void add_run_options(CLI::App* sub, IdentifyArgs& a) {
  sub->add_option("--checkpoint", a.opt.checkpoint_path, "Checkpoint file (written atomically)");
  sub->add_option("--checkpoint-every", a.opt.checkpoint_every, "Generations between checkpoints")
      ->needs("--checkpoint")  // without a checkpoint file it was ignored
      ->capture_default_str();
  sub->add_option("--resume", a.opt.resume_path,
                  "Continue from a checkpoint (same data, spec, flags)");
  sub->add_option("--mpi", a.mpi, "MPI: auto (when launched by mpirun/srun), on, off")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  sub->add_flag("--no-plots", a.no_plots,
                "Do not draw overlay_*.png and convergence.png (gmasim.command_figures); the "
                "CSV overlays are written");
  sub->add_flag("--quiet", a.quiet, "No progress on stderr, no summary");
}

// identify synthesize: the request table's options (gmasim/identify/synthetic_fields.hpp), then
// the choices of the record format (docs/data.md).
void add_synthetic_options(CLI::App* syn, SynthArgs& s) {
  s.options.add(syn, s.req, RequestOptions<SyntheticRequest>::Lists::Comma);
  syn->add_flag("--no-flux", s.no_flux, "Do not write the flux_T column");
  syn->add_option("--drive", s.drive,
                  "Drive column: current (current_A) or field (field_A_per_m: the rod's applied "
                  "field that the current produced)")
      ->check(CLI::IsMember({"current", "field"}))
      ->capture_default_str();
  syn->add_option("--response", s.response,
                  "Response column: displacement (displacement_um) or strain (strain_ppm of "
                  "the rod)")
      ->check(CLI::IsMember({"displacement", "strain"}))
      ->capture_default_str();
  syn->add_option("--offset", s.offset,
                  "Response reference: absolute, first_sample (written relative to the first "
                  "sample) or fitted (shifted by --response-offset)")
      ->check(CLI::IsMember({"absolute", "first_sample", "fitted"}))
      ->capture_default_str();
  syn->add_option("--initial-state", s.initial_state,
                  "Magnetic state the records start from (written as their initial_state key): "
                  "demagnetised, negative_remanence or positive_remanence")
      ->check(CLI::IsMember({"demagnetised", "negative_remanence", "positive_remanence"}))
      ->capture_default_str();
}

}  // namespace

Runner add_identify(CLI::App& app) {
  auto a = std::make_shared<IdentifyArgs>();
  auto s = std::make_shared<SynthArgs>();
  auto* sub = app.add_subcommand(
      "identify",
      "Identify model parameters from measurements: multi-island GA (pagmo2; MPI ranks under "
      "mpirun) + Levenberg-Marquardt; writes a calibrated model file and a fit report");
  sub->require_subcommand(0, 1);
  add_identify_files(sub, *a);
  add_search_options(sub, a->opt);
  add_refine_options(sub, *a);
  add_objective_options(sub, a->opt.objective);
  add_run_options(sub, *a);

  auto* syn = sub->add_subcommand(
      "synthesize",
      "Write synthetic measurements (CSV + manifest) from a model: biased sines at every "
      "temperature x current x frequency, with Gaussian noise");
  syn->add_option("--out", s->out, "Output directory")->required();
  add_model_options(syn, s->model);
  add_synthetic_options(syn, *s);

  return [a, s, sub, syn]() -> int {
    if (syn->parsed()) return run_synthesize(*s);
    if (sub->parsed()) return run_identify(*a);
    return -1;
  };
}

}  // namespace gmasim::cli
