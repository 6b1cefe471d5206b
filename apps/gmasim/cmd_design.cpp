// gmasim design: multi-objective design (NSGA-II, pagmo2) over declared model keys with bounds,
// objectives and constraints; the Pareto front as CSV, JSON and a figure; checkpoint and
// resume; MPI ranks under mpirun with the result of one process (gmasim/identify/design.hpp).
#include <fmt/format.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/identify/design.hpp"
#include "gmasim/identify/identify.hpp"
#include "gmasim/io/io.hpp"

namespace gmasim::cli {
namespace {

struct DesignArgs {
  ModelArgs model;
  DesignRequest req;
  std::vector<std::string> variables, minimize, maximize, constraints;
  std::string out = "out/design", mpi = "auto";
  bool plot = false, progress = false;
};

// "KEY=LOWER:UPPER".
DesignVariable variable_of(const std::string& text) {
  const auto eq = text.find('=');
  const auto colon = text.find(':', eq == std::string::npos ? 0 : eq);
  if (eq == std::string::npos || eq == 0 || colon == std::string::npos)
    throw InputError(fmt::format(
        "--variable '{}': expected KEY=LOWER:UPPER in the key's unit (a model key as `gmasim "
        "model show` lists it, or drive.current_pp_A / drive.current_min_A; e.g. --variable "
        "rod.length_m=0.04:0.1)",
        clip_for_message(text)));
  DesignVariable v;
  v.key = text.substr(0, eq);
  const auto lo = parse_list(text.substr(eq + 1, colon - eq - 1), "--variable " + v.key, "");
  const auto hi = parse_list(text.substr(colon + 1), "--variable " + v.key, "");
  if (lo.size() != 1 || hi.size() != 1)
    throw InputError(
        fmt::format("--variable '{}': give one lower and one upper bound", clip_for_message(text)));
  v.lower = lo[0];
  v.upper = hi[0];
  return v;
}

void build_request(DesignArgs& a, Communicator& comm) {
  for (const auto& v : a.variables) a.req.variables.push_back(variable_of(v));
  for (const auto& q : a.minimize)
    a.req.objectives.push_back({parse_design_quantity(q, "--minimize"), false});
  for (const auto& q : a.maximize)
    a.req.objectives.push_back({parse_design_quantity(q, "--maximize"), true});
  for (const auto& c : a.constraints) a.req.constraints.push_back(parse_design_constraint(c));
  a.req.comm = &comm;
  a.req.threads = threads_per_rank(a.req.threads, comm);  // 0: the cores over this node's ranks
  const ProgressFn p = stderr_progress("gmasim design: generations", a.progress);
  if (comm.rank() == 0 && p)
    a.req.progress = [p](int g, int n) {
      p(static_cast<std::size_t>(g), static_cast<std::size_t>(n));
    };
}

void print_front(const DesignRequest& r, const DesignResult& res) {
  std::string head;
  for (const auto& v : r.variables) head += fmt::format(" {:>22}", v.key);
  for (const auto& q : res.quantities) head += fmt::format(" {:>22}", q.label());
  fmt::print("  {} feasible designs on the Pareto front (of {} in the last generation):\n  {}\n",
             res.front.size(), res.population.size(), head);
  for (std::size_t i : res.front) {
    const DesignCandidate& c = res.population[i];
    std::string line;
    for (double x : c.x) line += fmt::format(" {:>22.6g}", x);
    for (double v : c.values) line += fmt::format(" {:>22.6g}", v);
    fmt::print("  {}\n", line);
  }
}

int run_design_body(DesignArgs& a, Communicator& comm) {
  const bool root = comm.rank() == 0;
  const ModelSpec spec = load_model_spec_args(a.model);
  build_request(a, comm);
  if (root) {
    // No output may overwrite an input: the checkpoint is written too (beside the model file it
    // must not replace, and the design's own files it must not be).
    std::vector<FileArg> outputs =
        files_in(a.out, {"design.csv", "design_population.csv", "design.json"}, "--out");
    if (!a.req.checkpoint_path.empty()) outputs.push_back({a.req.checkpoint_path, "--checkpoint"});
    require_outputs_distinct(model_inputs(a.model), outputs);
    prepare_output_dir(a.out, {"design"}, model_inputs(a.model));
  }
  const DesignResult res = run_design(spec, a.req);
  if (!root) return 0;
  auto files = write_report(a.out, "design", design_report(a.req, res));
  fmt::print("gmasim design  model: {}\n", model_label(a.model));
  fmt::print(
      "  NSGA-II: population {}, {} generations{} ({} evaluations) on {} rank(s) x {} threads "
      "in {:.2f} s\n",
      a.req.population, res.generations,
      res.resumed_from > 0 ? fmt::format(", resumed at generation {}", res.resumed_from) : "",
      res.evaluations, res.ranks, res.threads, res.wall_time_s);
  fmt::print("  drive: {:g} A p-p from {:g} A at {:g} Hz, metrics over the last of {:g} periods\n",
             a.req.current_pp_A, a.req.current_min_A, a.req.frequency_Hz, a.req.periods);
  print_front(a.req, res);
  if (res.front.empty())
    print_warning(
        "no feasible design in the last generation: loosen --constraint, widen the --variable "
        "bounds or run more --generations");
  if (a.plot) files.push_back(render_plot("design", a.out));
  if (!a.req.checkpoint_path.empty()) files.push_back(a.req.checkpoint_path);
  fmt::print("  wrote {}\n", fmt::join(files, ", "));
  return 0;
}

int run_design_cmd(DesignArgs& a) {
  return run_on_ranks(a.mpi, "design",
                      [&](Communicator& comm) { return run_design_body(a, comm); });
}

void add_problem_options(CLI::App* sub, DesignArgs& a) {
  sub->add_option("--variable", a.variables,
                  "A design variable KEY=LOWER:UPPER in the key's unit (repeatable): a model key "
                  "as `gmasim model show` lists it (what it derives follows), or "
                  "drive.current_pp_A / drive.current_min_A [A]")
      ->required();
  const std::string q = "Q: " + design_quantity_list();
  sub->add_option("--minimize", a.minimize, "An objective to minimise (repeatable). " + q);
  sub->add_option("--maximize", a.maximize,
                  "An objective to maximise (repeatable; two objectives or more in all: the "
                  "--minimize ones first, then these)");
  sub->add_option("--constraint", a.constraints,
                  "Q<=BOUND or Q>=BOUND, in Q's unit (repeatable; e.g. rods_mass_kg<=0.1, "
                  "temperature_rise_K@20<=10, current_peak_A<=10)");
  auto& r = a.req;
  sub->add_option("--current-min", r.current_min_A, "The drive's minimum current [A]")
      ->capture_default_str();
  sub->add_option("--current-pp", r.current_pp_A, "The drive's peak-to-peak current [A]")
      ->capture_default_str();
  sub->add_option("--frequency", r.frequency_Hz, "The drive's frequency [Hz]")
      ->capture_default_str();
  sub->add_option("--periods", r.periods, "Periods per run (the last is measured)")
      ->capture_default_str();
  sub->add_option("--dt", r.dt_s, "Time step [s] (0: the automatic rule)")->capture_default_str();
  sub->add_option("--reference-temperature", r.reference_temperature_C,
                  "Temperature of the small-signal markers (bandwidth_Hz, first_resonance_Hz) "
                  "[degC]")
      ->capture_default_str();
  sub->add_option("--bias", r.bias_A, "Bias of the small-signal markers [A]")
      ->capture_default_str();
}

void add_search_options(CLI::App* sub, DesignArgs& a) {
  auto& r = a.req;
  sub->add_option("--population", r.population, "NSGA-II population (a multiple of 4, >= 8)")
      ->capture_default_str();
  sub->add_option("--generations", r.generations,
                  "Generations (a resumed search continues up to this)")
      ->capture_default_str();
  sub->add_option("--seed", r.seed, "Random seed")->capture_default_str();
  sub->add_option("--threads", r.threads,
                  "Threads per rank evaluating the candidates (0: all cores); the result does "
                  "not depend on it")
      ->capture_default_str();
  sub->add_option("--checkpoint", r.checkpoint_path,
                  "Checkpoint file, written atomically after every generation");
  sub->add_flag("--resume", r.resume, "Continue from --checkpoint (same model, problem and flags)")
      ->needs("--checkpoint");
  sub->add_option("--mpi", a.mpi, "MPI: auto (when launched by mpirun/srun), on, off")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  sub->add_option("--out", a.out, "Output directory")->capture_default_str();
  sub->add_flag("--plot", a.plot, "Also draw <out>/design.png and .svg (matplotlib)");
  sub->add_flag("--progress", a.progress, "Progress on stderr even when it is not a terminal");
}

}  // namespace

Runner add_design(CLI::App& app) {
  auto a = std::make_shared<DesignArgs>();
  auto* sub = app.add_subcommand(
      "design",
      "Multi-objective design (NSGA-II, pagmo2; MPI ranks under mpirun): declared model keys "
      "with bounds, objectives from stroke, retention, hysteresis, bandwidth, mass, coil loss, "
      "and constraints; each candidate recompiled so that what its geometry derives follows. "
      "Writes design.csv (the Pareto front), design_population.csv and design.json");
  add_model_options(sub, a->model);
  add_problem_options(sub, *a);
  add_search_options(sub, *a);
  return [sub, a]() { return sub->parsed() ? run_design_cmd(*a) : -1; };
}

}  // namespace gmasim::cli
