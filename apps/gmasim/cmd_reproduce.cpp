// gmasim reproduce: the whole study of the paper, the claims table, the report.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <thread>

#include "commands.hpp"
#include "experiment_cli.hpp"
#include "gmasim/errors.hpp"
#include "gmasim/experiments/reproduce.hpp"
#include "gmasim/io/io.hpp"

namespace gmasim::cli {
namespace {

struct ReproduceArgs {
  ModelArgs model;
  std::string out = "out/reproduce", doc, python = "/usr/bin/python3";
  std::string doc_notes;  // markdown "### <claim id>" explanations of failing claims, for --doc
  std::string claims;     // claims file (data/claims.toml format); "" = the built-in claims
  std::vector<std::string> compare;  // other model files (readings) scored on the same claims
  int threads = 0;
  bool quick = false, no_figures = false;
};

// Progress of the stages on stderr. A terminal gets one updating line per stage; a pipe or a
// file (a CI log) a line every kEverySeconds while the study runs, from a heartbeat thread,
// so a log never sits silent for the 15 s of a stage, without one line per update.
class StageProgress {
 public:
  static constexpr auto kEvery = std::chrono::seconds(3);
  StageProgress() : tty_(isatty(fileno(stderr)) != 0), t0_(std::chrono::steady_clock::now()) {
    if (!tty_) beat_ = std::thread([this] { heartbeat(); });
  }
  ~StageProgress() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    if (beat_.joinable()) beat_.join();
  }
  StageProgress(const StageProgress&) = delete;
  StageProgress& operator=(const StageProgress&) = delete;
  // Model k of `models` (the study's model, then each --compare): its stages count after the
  // earlier models', so the heartbeat keeps going, and counting, through the compared models.
  ProgressFn fn(std::size_t k = 0, std::size_t models = 1) {
    return [this, k, models](std::size_t done, std::size_t total) {
      const std::lock_guard<std::mutex> lock(mutex_);
      done_ = k * total + done;
      total_ = models * total;
      done = done_;
      total = total_;
      if (!tty_) return;
      fmt::print(stderr, "\rreproduce: stage {}/{}", done, total);
      if (done == total) fmt::print(stderr, "\n");
    };
  }

 private:
  void heartbeat() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, kEvery, [this] { return stop_; })) {
      const double el =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
      if (total_ == 0)
        fmt::print(stderr, "reproduce: the first stage is running, {:.0f} s elapsed\n", el);
      else
        fmt::print(stderr, "reproduce: {}/{} stages done, {:.0f} s elapsed\n", done_, total_, el);
      std::fflush(stderr);
    }
  }
  bool tty_;
  std::chrono::steady_clock::time_point t0_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::size_t done_ = 0, total_ = 0;
  std::thread beat_;
};

int run_reproduce_cmd(const ReproduceArgs& a) {
  const Model model = load_model_args(a.model);
  const ClaimsData claims = a.claims.empty() ? builtin_claims() : load_claims(a.claims);
  if (!a.doc_notes.empty() && a.doc.empty())
    throw InputError("--doc-notes " + a.doc_notes +
                     ": explains the claims of --doc; give --doc too");
  const auto notes = a.doc_notes.empty() ? std::vector<std::pair<std::string, std::string>>{}
                                         : load_claim_notes(a.doc_notes);
  ReproduceOptions o;
  o.threads = a.threads;
  o.quick = a.quick;
  o.claims = &claims;
  // Every input (model, claims, notes, the compared models) against the report directory
  // (report.md, claims.*, data/, figures/: any file in it) and --doc.
  std::vector<FileArg> inputs = model_inputs(a.model);
  inputs.push_back({a.claims, "--claims"});
  inputs.push_back({a.doc_notes, "--doc-notes"});
  for (const auto& c : a.compare) inputs.push_back({c, "--compare"});
  if (a.out.empty()) ensure_output_dir(a.out);
  std::vector<FileArg> outputs = files_in(a.out, {"*"}, "--out");
  for (const char* sub : {"data", "figures"})
    outputs.push_back({(std::filesystem::path(a.out) / sub / "*").string(), "--out"});
  if (!a.doc.empty()) outputs.push_back({a.doc, "--doc"});
  require_outputs_distinct(inputs, outputs);
  ensure_output_dir(a.out);
  const std::size_t models = 1 + a.compare.size();
  ReproduceResult r;
  std::vector<ComparedModel> compared;
  {
    StageProgress progress;
    r = run_reproduce(model, o, progress.fn(0, models));
    write_reproduce_outputs(model, r, a.out, a.no_figures ? std::string() : a.python,
                            python_package_path());
    for (std::size_t k = 0; k < a.compare.size(); ++k) {
      const Model other = load_model(a.compare[k]);
      const ReproduceResult o2 = run_reproduce(other, o, progress.fn(k + 1, models));
      compared.push_back(
          {std::filesystem::path(a.compare[k]).stem().string(), o2.model_readings, o2.claims});
    }
  }
  if (!a.doc.empty()) write_reproduction_doc(r, compared, a.doc, a.out, notes);
  const ClaimCount n = count_claims(r.claims);
  fmt::print("gmasim reproduce  model: {}\n  {}\n  claims: {}\n", model_label(a.model),
             r.model_readings, claims.source);
  fmt::print("  {}\n", fitted_predicted_line(n));
  fmt::print("  {} of {} applicable claims pass ({} claims); study took {:.1f} s\n", n.pass,
             n.applicable, r.claims.size(), r.wall_time_s);
  if (const auto failing = unexplained_failures(r.claims, {}); !failing.empty())
    fmt::print("  failing: {}; why each fails: {} (its '### <claim id>' sections){}\n",
               fmt::join(failing, ", "),
               a.doc_notes.empty() ? std::string("docs/failing_claims.md") : a.doc_notes,
               a.doc.empty() ? "" : ", and in " + a.doc);
  for (const auto& t : r.trends)
    fmt::print("  trend: {} {} ({:+.3g} /A, paper {:+.3g} /A)\n", t.what, t.pass ? "PASS" : "FAIL",
               t.ours_slope, t.paper_slope);
  if (!a.doc.empty())
    for (const auto& id : unexplained_failures(r.claims, notes))
      fmt::print(stderr, "gmasim reproduce: warning: failing claim {} has no explanation{}\n", id,
                 a.doc_notes.empty() ? " (--doc-notes)" : " in " + a.doc_notes);
  fmt::print("  wrote {}/report.md, {}/claims.csv|json, {}/data/*.csv|json{}\n", a.out, a.out,
             a.out, a.doc.empty() ? "" : ", " + a.doc);
  return 0;
}

}  // namespace

Runner add_reproduce(CLI::App& app) {
  auto a = std::make_shared<ReproduceArgs>();
  auto* sub = app.add_subcommand("reproduce",
                                 "Run the paper's whole study (sweeps, FRF, tracking, ablation, "
                                 "20-150 degC) and write the report "
                                 "with the claims table");
  add_model_options(sub, a->model);
  sub->add_option("--out", a->out, "Output directory (report.md, claims, data/, figures/)")
      ->capture_default_str();
  sub->add_option(
      "--doc", a->doc,
      "Also write this markdown page (e.g. docs/reproduction.md) with the claims table");
  sub->add_option(
      "--doc-notes", a->doc_notes,
      "With --doc: markdown whose '### <claim id>' sections explain failing claims "
      "(e.g. docs/failing_claims.md); each failing claim's explanation goes into the page");
  sub->add_option("--threads", a->threads, "Worker threads for the sweeps [-]; 0 = all cores")
      ->capture_default_str();
  sub->add_flag("--quick", a->quick, "Smaller grids (for tests)");
  sub->add_option(
      "--compare", a->compare,
      "Also score these model files (e.g. each calibrated reading) on the claims; with --doc, "
      "adds a table of which claims each meets");
  sub->add_option("--claims", a->claims,
                  "Score these claims (TOML, the format of data/claims.toml: docs/claims.md) "
                  "instead of the built-in ones");
  sub->add_flag("--no-figures", a->no_figures, "Do not render figures (no Python)");
  sub->add_option("--python", a->python, "Python interpreter that renders the figures")
      ->capture_default_str();
  return [a, sub]() -> int { return sub->parsed() ? run_reproduce_cmd(*a) : -1; };
}

}  // namespace gmasim::cli
